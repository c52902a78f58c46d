"""Missions: files, the executor that connects planners to vehicles, and their metrics."""
