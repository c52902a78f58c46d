"""The station: I/O and scheduling around the flight core (link, recorder, loop, guardian)."""
