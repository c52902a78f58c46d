"""The pure flight core: one tick's inputs in, one tick's decisions out (no I/O, no clock).

`FlightCore.step(TickInputs) -> TickOutputs` runs the estimator, the supervisor with its
controllers, and the station's own rules (at rest, link-down accounting, landing states). The
station around it polls, steps, executes and records; a rerun steps the recorded inputs.
"""

from gcs.core.flight_core import FlightCore
from gcs.core.inputs import TickInputs, TickRecord
from gcs.core.outputs import TickOutputs

__all__ = ["FlightCore", "TickInputs", "TickOutputs", "TickRecord"]
