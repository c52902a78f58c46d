"""The bundled simulated vehicle: physics, ArduCopter-like autopilot, sensors, MAVLink endpoints."""
