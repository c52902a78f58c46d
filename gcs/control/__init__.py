"""The controllers: PID, altitude and position loops, and the autopilot's throttle curve."""
