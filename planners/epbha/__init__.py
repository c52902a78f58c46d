"""EPBHA, the thesis's proximity-based obstacle avoidance (Ch. 8): the planner and its parts."""
