"""What one tick writes to the recording: its inputs (for a rerun), its decisions, its timing."""

from __future__ import annotations

from gcs import topics
from gcs.core.inputs import TickInputs, TickRecord
from gcs.core.outputs import TickOutputs
from gcs.station.loop import TickTiming
from gcs.station.types import LoopSample, Recorder


def record_tick(rec: Recorder, inputs: TickInputs, out: TickOutputs,
                timing: TickTiming | None) -> None:
    """Write the tick: its intents, its inputs (the counts of the records already written on
    their topics), the supervisor's transitions, the estimate, the controllers' outputs, the
    override sent and the loop's timing."""
    t_s = inputs.t_s
    for it in inputs.intents:
        rec.put(topics.INTENT, t_s, it)
    rec.put(topics.TICK, t_s, TickRecord.of(inputs, out.at_rest, out.state, out.link_lost))
    sup = out.supervisor
    for tr in sup.transitions:
        rec.put(topics.SUPERVISOR, t_s, tr)
    rec.put(topics.ESTIMATE, t_s, out.estimate)
    if out.alt is not None:
        rec.put(topics.ALT_CONTROLLER, t_s, out.alt)
    if out.position is not None:
        rec.put(topics.POSITION_CONTROLLER, t_s, out.position)
    if sup.command is not None:
        rec.put(topics.RC_OVERRIDE, t_s, sup.command)
    if timing is not None:
        rec.put(topics.LOOP, t_s, LoopSample(
            tick=timing.k, period_ms=timing.period_s * 1e3, jitter_ms=timing.jitter_s * 1e3,
            lateness_ms=timing.lateness_s * 1e3, compute_ms=timing.compute_s * 1e3,
            overrun=timing.overrun))
