"""The pure flight core: one tick's inputs in, one tick's decisions out (no I/O, no clock).

`FlightCore.step(TickInputs) -> TickOutputs` (flight_core, inputs, outputs) runs the estimator,
the supervisor with its controllers, and the station's own rules (at rest, link-down accounting,
landing states). The station around it polls, steps, executes and records; a rerun steps the
recorded inputs. Nothing is imported here: the guardian process needs only `landing`, and
starting it must stay quick.
"""
