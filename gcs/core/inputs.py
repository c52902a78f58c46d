"""One control tick's inputs, and the record of them a recording keeps.

`TickInputs` is everything the flight core consumes in a tick: the telemetry records the tick
brought (in the order they came), the pilot's intents, and what the link knows of the vehicle.
A recording keeps the records on their own topics; `/gcs/tick` holds a `TickRecord`, the inputs
with each tuple replaced by its length (and the tick's verdict beside them), from which
`TickRecord.inputs` rebuilds the `TickInputs` given the topics' records in order.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from firmware_link.records import (
    Attitude,
    Barometer,
    Imu,
    MocapPose,
    Rangefinder,
    TelemetryRecord,
)
from gcs.supervisor import Intent, SupervisorState, VehicleStatus

NEVER_S = 1.0e9
"""Stand-in for 'never' in recorded times: finite, so a recording gives it back unchanged."""


@dataclass(frozen=True, slots=True)
class TickInputs:
    """What one tick consumes. Each tuple keeps the order the records arrived in."""

    tick: int
    t_s: float
    dt_s: float
    vehicle: VehicleStatus
    imus: tuple[Imu, ...] = ()
    sonars: tuple[Rangefinder, ...] = ()
    attitudes: tuple[Attitude, ...] = ()
    baros: tuple[Barometer, ...] = ()
    mocaps: tuple[MocapPose, ...] = ()
    intents: tuple[Intent, ...] = ()

    @staticmethod
    def of(tick: int, t_s: float, dt_s: float, vehicle: VehicleStatus,
           records: Iterable[TelemetryRecord], intents: Iterable[Intent] = ()) -> TickInputs:
        """The inputs of a tick that polled `records` (other record types are not the core's)."""
        imus: list[Imu] = []
        sonars: list[Rangefinder] = []
        attitudes: list[Attitude] = []
        baros: list[Barometer] = []
        mocaps: list[MocapPose] = []
        for r in records:
            if isinstance(r, Imu):
                imus.append(r)
            elif isinstance(r, Rangefinder):
                sonars.append(r)
            elif isinstance(r, Attitude):
                attitudes.append(r)
            elif isinstance(r, Barometer):
                baros.append(r)
            elif isinstance(r, MocapPose):
                mocaps.append(r)
        return TickInputs(tick, t_s, dt_s, vehicle, tuple(imus), tuple(sonars),
                          tuple(attitudes), tuple(baros), tuple(mocaps), tuple(intents))


@dataclass(frozen=True, slots=True)
class TickRecord:
    """/gcs/tick payload: a tick's `TickInputs` with its tuples as counts (their records are on
    their own topics, the next ones in recorded order), and the tick's verdict (`at_rest`, the
    supervisor's state after it, the link lost) for a reader who wants no rerun."""

    tick: int
    t_s: float
    dt_s: float
    imu_n: int
    rangefinder_n: int
    attitude_n: int
    mocap_n: int
    baro_n: int
    intent_n: int
    at_rest: bool  # disarmed: the estimator was told the vehicle stands still
    vehicle_seen: bool
    armed: bool
    vehicle_mode: int
    heartbeat_t_s: float
    frame_age_s: float
    state: SupervisorState  # after the tick
    link_lost: bool

    @staticmethod
    def of(inputs: TickInputs, at_rest: bool, state: SupervisorState,
           link_lost: bool) -> TickRecord:
        """The record of `inputs` and of the verdict the core reached on them."""
        v = inputs.vehicle
        return TickRecord(
            tick=inputs.tick, t_s=inputs.t_s, dt_s=inputs.dt_s, imu_n=len(inputs.imus),
            rangefinder_n=len(inputs.sonars), attitude_n=len(inputs.attitudes),
            mocap_n=len(inputs.mocaps), baro_n=len(inputs.baros), intent_n=len(inputs.intents),
            at_rest=at_rest, vehicle_seen=v.seen, armed=v.armed, vehicle_mode=v.mode,
            heartbeat_t_s=v.heartbeat_t_s, frame_age_s=v.frame_age_s, state=state,
            link_lost=link_lost)

    @property
    def vehicle(self) -> VehicleStatus:
        return VehicleStatus(seen=self.vehicle_seen, armed=self.armed, mode=self.vehicle_mode,
                             heartbeat_t_s=self.heartbeat_t_s, frame_age_s=self.frame_age_s)

    def inputs(self, imus: tuple[Imu, ...], sonars: tuple[Rangefinder, ...],
               attitudes: tuple[Attitude, ...], baros: tuple[Barometer, ...],
               mocaps: tuple[MocapPose, ...], intents: tuple[Intent, ...]) -> TickInputs:
        """The `TickInputs` this record counts, given the records it counted."""
        got = (len(imus), len(sonars), len(attitudes), len(baros), len(mocaps), len(intents))
        want = (self.imu_n, self.rangefinder_n, self.attitude_n, self.baro_n, self.mocap_n,
                self.intent_n)
        if got != want:
            raise ValueError(f"tick {self.tick} counted {want} records, was given {got}")
        return TickInputs(self.tick, self.t_s, self.dt_s, self.vehicle, imus, sonars, attitudes,
                          baros, mocaps, intents)
