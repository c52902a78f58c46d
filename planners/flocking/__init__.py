"""Leader–follower flocking of the thesis (Ch. 9): the formation tree, the planner and its parts."""
