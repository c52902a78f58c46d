"""Flight recording to MCAP, reading, recovery, replay, export and plots."""
