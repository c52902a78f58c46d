"""A schedule's faults put on a lockstep flight, and the flight's trace kept while it flies.

`FaultPlan.attach(sitl)` is called by the bundled SITL's opener (`lab.lockstep`) when a flight
asks for a schedule: the vehicle links get the link faults (`PortFaults`), the SITL the stalls
(`Stopping`), each vehicle the sensor faults (`sitl.sensor_hook`), and a tick hook the vehicle's
own mode change and the truth's record. `watch_station` is called for each station once the
session has built it: the pilot's kill, quit, land and `+` act through the station's own
intents, and the phases a fault may be timed to are read off its ticks. Nothing here reads a
wall clock or draws a random number the seed does not decide, so `seed + schedule` replays.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import replace
from typing import Any

from firmware_link.records import FlightMode
from gcs.flight_plan import FlightPlan
from gcs.station.station import Station, StationSnapshot
from gcs.supervisor import SupervisorState
from lab.faultsearch.schedule import (
    LINK_KINDS,
    PILOT_KINDS,
    Fault,
    Schedule,
    flight_span_s,
    load_schedule,
)
from lab.faultsearch.trace import StationSample, Trace, TruthSample
from lab.lockstep import install as install_lockstep
from lab.lockstep import use_schedules
from sitl.battery import BatteryState
from sitl.lockstep import LockstepSitl
from sitl.sensors.imu import ImuSample
from sitl.sensors.sonar import SonarSample

_WAYS = {"fade_down": ("down",), "fade_up": ("up",), "fade_both": ("down", "up"),
         "loss_down": ("down",), "loss_up": ("up",), "loss_both": ("down", "up"),
         "bitflip": ("down", "up")}
PLATEAU_S = 1.0  # a setpoint unchanged this long is a plateau (a step or a descent leaves it)
MOVE_M = 0.02


class RunCapped(BaseException):
    """A run reached its simulated-time cap (a station that waits for ever on a vehicle that
    never disarms, say). Not an Exception: nothing on the way may take it for the flight's."""


class FaultPlan:
    """One run's faults, on one lockstep SITL and its stations; `stop_at_s`: the run's cap in
    simulated seconds (RunCapped out of the SITL's tick past it)."""

    def __init__(self, schedule: Schedule, seed: int = 0, stop_at_s: float = math.inf) -> None:
        self.schedule = schedule
        self.seed = seed
        self.stop_at_s = stop_at_s
        self.trace = Trace()
        self.anchors = self.trace.anchors
        self._link = schedule.of(LINK_KINDS)
        self._stalls = schedule.of(frozenset({"stall"}))
        self._pending = [f for f in schedule.faults if f.kind in PILOT_KINDS]
        self._modes = [f for f in schedule.faults if f.kind == "mode_land"]
        self.sitl: LockstepSitl | None = None

    # ------------------------------------------------------------ the SITL's side
    def attach(self, sitl: LockstepSitl) -> FaultPlan:
        """Put the faults on `sitl`; the link faults for its vehicle ports (this object)."""
        self.sitl = sitl
        if self._stalls:
            sitl.stall = self
        w = sitl.sim.world
        lsb = w.sensors.imu.acc_range_g * 9.80665 / 32768  # one count of the accelerometer
        for rt in sitl.sim.vehicles:
            rt.sensor_hook = SensorFaults(self, lsb)
        self.trace.boxes = w.boxes
        self.trace.body_radius_m = w.vehicle.body_radius_m
        self.trace.gear_m = w.vehicle.gear_height_m
        sitl.tick_hooks.append(self._on_tick)
        return self

    def faded(self, way: str, t_s: float) -> bool:
        """PortFaults: a fade of `way` is on."""
        return any(way in _WAYS[f.kind] and f.kind.startswith("fade")
                   and f.active(t_s, self.anchors) for f in self._link)

    def loss_at(self, way: str, t_s: float) -> float:
        """PortFaults: the strongest loss (or bit-flip) rate on `way` now."""
        rates = [f.size for f in self._link if not f.kind.startswith("fade")
                 and way in _WAYS[f.kind] and f.active(t_s, self.anchors)]
        return max(rates, default=0.0)

    def reached_s(self, t_s: float) -> float:
        """Stopping: how far the SITL has run when the clock reads `t_s`."""
        for f in self._stalls:
            b = f.begins_s(self.anchors)
            if b is not None and b <= t_s < b + f.length_s:
                return b
        return t_s

    def resumes_s(self, t_s: float) -> float:
        """Stopping: the earliest time at or after `t_s` at which the SITL runs."""
        for f in self._stalls:
            b = f.begins_s(self.anchors)
            if b is not None and b <= t_s < b + f.length_s:
                return b + f.length_s
        return t_s

    def _on_tick(self, t_s: float) -> None:
        assert self.sitl is not None
        if t_s > self.stop_at_s:
            raise RunCapped(f"the run reached its cap of {self.stop_at_s:g} simulated s")
        rt = self.sitl.sim.vehicles[0]
        for f in list(self._modes):
            b = f.begins_s(self.anchors)
            if b is not None and t_s >= b:
                self._modes.remove(f)
                if rt.autopilot.state.armed:
                    rt.autopilot.land_with_pause()  # what a firmware failsafe does
                self.trace.events.append((t_s, f.kind))
        tr = rt.vehicle.truth
        self.trace.truth.append(TruthSample(
            t_s, -tr.pos_n[2], tr.vel_n[2], (tr.pos_n[0], tr.pos_n[1]), tr.on_ground,
            tr.collided_with, rt.autopilot.state.armed, int(rt.autopilot.state.mode)))

    # ------------------------------------------------------------ the station's side
    def watch_station(self, sysid: int, station: Station) -> None:
        """Act the pilot's faults through `station` and time the phases on its ticks (the
        first vehicle only: a search flies one)."""
        if sysid == 1:
            station.add_listener(_StationWatch(self, station))


class _StationWatch:
    """A station listener: phases, the pilot's hand, the station's record."""

    def __init__(self, plan: FaultPlan, station: Station) -> None:
        self.plan = plan
        self.station = station
        self._plateau: tuple[float, float] | None = None  # (setpoint, since)
        self._mode: int | None = None

    def __call__(self, snap: StationSnapshot) -> None:
        p = self.plan
        t = snap.t_s
        p.trace.station.append(StationSample(
            t, snap.state.value, snap.alt_setpoint_m,
            snap.estimate.alt_m if snap.estimate is not None else None,
            snap.command.throttle_us, snap.link_lost))
        self._phases(snap)
        for f in list(p._pending):
            b = f.begins_s(p.anchors)
            if b is not None and t >= b:
                p._pending.remove(f)
                self._act(f, snap)
                p.trace.events.append((t, f.kind))

    def _phases(self, snap: StationSnapshot) -> None:
        a = self.plan.anchors
        t = snap.t_s
        if snap.state is SupervisorState.TAKEOFF:
            a.setdefault("takeoff", t)
        if snap.state is SupervisorState.HOLD:
            a.setdefault("hold", t)
        if snap.state in (SupervisorState.QUITTING, SupervisorState.VEHICLE,
                          SupervisorState.LINK_LOST, SupervisorState.KILLED) and "hold" in a:
            a.setdefault("landing", t)
        if snap.armed and snap.vehicle_mode >= 0:
            if self._mode is not None and snap.vehicle_mode != self._mode:
                a.setdefault("mode", t)
            self._mode = snap.vehicle_mode
        sp = snap.alt_setpoint_m
        if sp is None or snap.state is not SupervisorState.HOLD:
            self._plateau = None
            return
        if self._plateau is None or abs(sp - self._plateau[0]) > 1e-6:
            old = self._plateau
            if old is not None and t - old[1] >= PLATEAU_S:
                if sp > old[0] + MOVE_M:
                    a.setdefault("step", t)
                elif sp < old[0] - MOVE_M:
                    a.setdefault("landing", t)
            if old is None or abs(sp - old[0]) > MOVE_M or t - old[1] < PLATEAU_S:
                self._plateau = (sp, t)

    def _act(self, f: Fault, snap: StationSnapshot) -> None:
        st = self.station
        if f.kind == "pilot_kill":
            st.kill()
        elif f.kind == "pilot_quit":
            st.quit()
        elif f.kind == "pilot_land":
            st.set_mode(FlightMode.LAND)
        elif f.kind == "pilot_plus" and snap.alt_setpoint_m is not None:
            st.alt_hold(True, snap.alt_setpoint_m + f.size)


class SensorFaults:
    """`sitl.sensor_hook.SensorHook`: the schedule's sensor faults on one vehicle's readings."""

    def __init__(self, plan: FaultPlan, acc_lsb: float) -> None:
        self.plan = plan
        self.acc_lsb = acc_lsb
        self._faults = [f for f in plan.schedule.faults if f.kind.startswith(
            ("sonar_", "imu_", "battery_"))]
        self._last_imu: ImuSample | None = None
        self._frozen_imu: ImuSample | None = None
        self._last_sonar: SonarSample | None = None
        self._late: deque[tuple[float, SonarSample]] = deque()

    def _on(self, kind: str, t_s: float) -> Fault | None:
        for f in self._faults:
            if f.kind == kind and f.active(t_s, self.plan.anchors):
                return f
        return None

    def imu(self, t_s: float, sample: ImuSample) -> ImuSample:
        if not self._faults:
            return sample
        out = sample
        if self._on("imu_stall", t_s) is not None:
            if self._frozen_imu is None:
                self._frozen_imu = self._last_imu or sample
            out = replace(self._frozen_imu, t_s=sample.t_s)
        else:
            self._frozen_imu = None
        spike = self._on("imu_spike", t_s)
        if spike is not None:
            ax, ay, az = out.acc_b
            rx, ry, rz = out.acc_raw
            lsb = self.acc_lsb
            dz = round(spike.size / lsb)
            out = replace(out, acc_b=(ax, ay, az + dz * lsb),
                          acc_raw=(rx, ry, max(-32768, min(32767, rz + dz))))
        self._last_imu = sample
        return out

    def sonar(self, t_s: float, sample: SonarSample | None) -> SonarSample | None:
        if not self._faults:
            return sample
        late = self._on("sonar_late", t_s)
        if sample is not None and late is not None:
            self._late.append((t_s + late.size, sample))
            sample = None
        while self._late and self._late[0][0] <= t_s:
            _, held = self._late.popleft()
            sample = replace(held, t_s=t_s)
        if sample is None:
            return None
        if self._on("sonar_dropout", t_s) is not None:
            # the echo never came back: the HC-SR04 reads 0, as over carpet
            return replace(sample, distance_m=0.0, valid=False)
        if self._on("sonar_stuck", t_s) is not None and self._last_sonar is not None:
            return replace(self._last_sonar, t_s=sample.t_s)
        self._last_sonar = sample
        return sample

    def battery(self, t_s: float, state: BatteryState) -> BatteryState:
        sag = self._on("battery_sag", t_s) if self._faults else None
        if sag is None:
            return state
        return replace(state, voltage_v=max(0.0, state.voltage_v - sag.size))


def plan_of(given: Any, seed: int, flight: FlightPlan | None = None) -> FaultPlan:
    """A FaultPlan from what a flight's options carry: a plan, a schedule, or a file path
    (checked to fit in `flight` when given)."""
    if isinstance(given, FaultPlan):
        return given
    if isinstance(given, Schedule):
        return FaultPlan(given, seed)
    span = flight_span_s(flight) if flight is not None else None
    return FaultPlan(load_schedule(given, span), seed)


def install() -> None:
    """Lockstep flights on the bundled SITL, fault schedules included (idempotent)."""
    install_lockstep()
    use_schedules(plan_of)
