"""What needs the station and the simulator in one process: lockstep flights, campaigns."""
