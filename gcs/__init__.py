"""The station: estimation, control, the fixed-rate loop, teleop, missions and the CLI."""
