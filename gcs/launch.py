"""One bring-up, arming and take-off request for every flight: `fly`'s vehicle and a team's.

Arming is the dangerous wait. A firmware disarms a vehicle that stands armed on the floor with
the throttle at minimum (ArduCopter 3.2.1 after 15 s, 4.x after DISARM_DELAY), so arming one
vehicle after another and taking off once the last is ready loses the first. Every vehicle is
put in STABILIZE with the throttle at minimum and left to rest (the estimators learn the
accelerometer's bias from a vehicle known to stand still), asked to arm in one go, and the
take-off may follow the moment the last one is armed. A firmware refuses to arm for a while
after boot (4.x's pre-arm passes ≈ 24 s after it, 3.2.1's "PreArm: ..." until its sensors
settle), and a loaded machine slows everyone: each vehicle's arm is asked again every second
(its supervisor's) until a stated deadline (`LaunchRules.arm_timeout_s`, the mission's
`flight.arm_timeout_s` or `--arm-timeout`), and each new refusal reason the firmware gives
(STATUSTEXT "PreArm: ...", a refused COMMAND_ACK) is told as it comes. Should the last still be
refused when the first armed has stood as long as the shortest auto-disarm allows, the armed
ones are disarmed and asked again with the rest, so none is left to its firmware's disarm. At
the deadline every vehicle is disarmed and the launch fails, naming each vehicle not armed and
its last reason, before anything leaves the floor. One vehicle is a team of one: `fly` and a
mission refuse and abort alike.

Decisions follow the supervisor's outcomes (`gcs.supervisor.Outcome`), never the words of its
notes; the words go into the failure's line for the pilot. How to look at the vehicles and how
to let time pass stay the caller's (`LaunchPort`): `fly` checks its flight phase at every look
and, in lockstep, runs one tick between looks; a team polls at 10 Hz on the team's clock.
"""

from __future__ import annotations

import enum
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Protocol

from firmware_link.records import FlightMode
from gcs.errors import FlightFailed
from gcs.station.types import StationEvent
from gcs.supervisor import ARM_FAILED, Outcome, OutcomeKind, SupervisorParams, SupervisorState

STICK_MID_US, STICK_MIN_US = 1500, 1000
MODE_TIMEOUT_S = 10.0
REST_S = 3.0  # disarmed on the floor first: the estimators learn the accelerometer bias at rest
ARM_TIMEOUT_S = 30.0  # from the request (4.x's pre-arm refuses ~24 s after boot)
# the supervisors keep asking a little past the launch's deadline: the launch decides, at it
ARM_ASK_GRACE_S = 5.0
MAV_CMD_COMPONENT_ARM_DISARM = 400
MAV_RESULTS = {1: "TEMPORARILY_REJECTED", 2: "DENIED", 3: "UNSUPPORTED", 4: "FAILED",
               5: "IN_PROGRESS"}
# Take-off must be asked this long before the first-armed vehicle's auto-disarm: the request
# reaches the vehicle on the next tick, and the throttle has to leave minimum there.
AUTO_DISARM_MARGIN_S = 5.0
TAKEOFF_ASK_S = 2.0  # the supervisor takes a take-off request on its next tick
RECENT_TEXT_S = 5.0  # a vehicle's text older than this explains nothing


class LaunchFailed(FlightFailed):
    """The vehicles were not armed and sent off the floor as commanded (exit 3)."""


class LaunchStage(enum.Enum):
    """What a launch tells its caller as it goes (a mission records these as events)."""

    ARMING = "arming"
    ARM_REFUSED = "arm_refused"  # a vehicle's firmware refused (a new reason): asked again
    ARMED = "armed"
    DISARMED = "disarmed"  # the launch failed: every vehicle asked to disarm on the floor


class LaunchView(Protocol):
    """What a launch reads of one vehicle's station snapshot."""

    @property
    def t_s(self) -> float: ...
    @property
    def armed(self) -> bool: ...
    @property
    def vehicle_mode(self) -> int: ...
    @property
    def state(self) -> SupervisorState: ...
    @property
    def outcomes(self) -> tuple[Outcome, ...]: ...
    @property
    def events(self) -> Sequence[StationEvent]: ...


class LaunchStation(Protocol):
    """What a launch asks of one vehicle's station."""

    @property
    def supervisor_params(self) -> SupervisorParams: ...
    def set_sticks(self, roll_us: int, pitch_us: int, yaw_us: int, throttle_us: int) -> None: ...
    def set_mode(self, mode: FlightMode) -> None: ...
    def request_arm(self, wait_s: float | None = None) -> None: ...
    def request_disarm(self) -> None: ...
    def alt_hold(self, on: bool, setpoint_m: float | None = None,
                 rate_mps: float | None = None) -> None: ...


class LaunchPort(Protocol):
    """The caller's ways of looking at its vehicles and of letting time pass."""

    def now_s(self) -> float:
        """The stations' clock."""
        ...

    def look(self, vehicle: int) -> LaunchView:
        """The vehicle's latest snapshot; raises the caller's own error when its flight is off
        (a dead loop, a state its phase does not allow)."""
        ...

    def idle(self) -> None:
        """Between looks."""
        ...

    def rest(self, seconds: float) -> None:
        """Let `seconds` pass on the stations' clock."""
        ...

    def told(self, stage: LaunchStage, detail: str) -> None:
        """A stage reached (a mission records it)."""
        ...


@dataclass(frozen=True, slots=True)
class LaunchRules:
    """How long each step may take."""

    rest_s: float = REST_S
    arm_timeout_s: float = ARM_TIMEOUT_S
    mode_timeout_s: float = MODE_TIMEOUT_S
    margin_s: float = AUTO_DISARM_MARGIN_S


def vehicle_said(view: LaunchView, recent_s: float = RECENT_TEXT_S) -> str:
    """The vehicle's last text if it is recent, as " (vehicle: ...)" for a failure's line."""
    texts = [e.text for e in view.events if e.text.startswith("vehicle:")
             and view.t_s - e.t_s <= recent_s]
    return f" ({texts[-1]})" if texts else ""


def arm_refusal(view: LaunchView, after_s: float) -> str:
    """The firmware's last reason for refusing to arm since `after_s`: its "PreArm: ..." /
    "Arm: ..." text, else a refused COMMAND_ACK's result; "" when it gave none."""
    text = ack = ""
    for e in view.events:
        if e.t_s < after_s:
            continue
        said = e.text.removeprefix("vehicle: ")
        if said != e.text and said.lower().startswith(("prearm", "arm:", "arm ")):
            text = said
        elif e.text.startswith(f"vehicle refused command {MAV_CMD_COMPONENT_ARM_DISARM} "):
            code = e.text.rpartition("result ")[2].rstrip(")")
            name = MAV_RESULTS.get(int(code), code) if code.isdigit() else code
            ack = f"COMMAND_ACK {name}"
    return text or ack


def since(view: LaunchView, t_s: float, kinds: frozenset[OutcomeKind]) -> Outcome | None:
    """The last outcome of `kinds` at or after `t_s`."""
    found = [o for o in view.outcomes if o.t_s >= t_s and o.kind in kinds]
    return found[-1] if found else None


@dataclass
class Launch:
    """Bring up, arm together and ask for the take-off of the vehicles of `stations`."""

    stations: Mapping[int, LaunchStation]
    port: LaunchPort
    rules: LaunchRules = field(default_factory=LaunchRules)
    armed_at_s: dict[int, float] = field(default_factory=dict)
    takeoff_asked_s: float | None = None

    def auto_disarm_s(self) -> float:
        """The shortest auto-disarm delay of the vehicles' firmwares."""
        return min(st.supervisor_params.auto_disarm_s for st in self.stations.values())

    def bring_up(self) -> None:
        """Level sticks, throttle at minimum, STABILIZE on every vehicle; wait until each is."""
        for st in self.stations.values():
            st.set_sticks(STICK_MID_US, STICK_MID_US, STICK_MID_US, STICK_MIN_US)
            st.set_mode(FlightMode.STABILIZE)
        port = self.port
        deadline = port.now_s() + self.rules.mode_timeout_s
        while True:
            late = [v for v in self.stations
                    if port.look(v).vehicle_mode != FlightMode.STABILIZE]
            if not late:
                return
            if port.now_s() >= deadline:
                raise LaunchFailed(f"arming: vehicles {late} did not switch to STABILIZE "
                                   f"within {self.rules.mode_timeout_s:g} s")
            port.idle()

    def arm(self) -> dict[int, float]:
        """Bring up, rest, then arm every vehicle at once, each asked again until the deadline
        (see the module's docstring); when each was seen armed. LaunchFailed, every vehicle
        disarmed, when they were not."""
        self.bring_up()
        port = self.port
        port.rest(self.rules.rest_s)
        asked_at = port.now_s()
        limit_s = self.rules.arm_timeout_s
        port.told(LaunchStage.ARMING, f"{len(self.stations)} vehicle(s) together, each asked "
                  f"again until {limit_s:g} s")
        for st in self.stations.values():
            st.request_arm(wait_s=limit_s + ARM_ASK_GRACE_S)
        budget_s = self.auto_disarm_s() - self.rules.margin_s
        deadline = asked_at + limit_s
        self.armed_at_s = {}
        failed: dict[int, str] = {}
        reasons: dict[int, str] = {}
        round_at = dict.fromkeys(self.stations, asked_at)  # each vehicle's latest request
        while True:
            now = port.now_s()
            for v in self.stations:
                view = port.look(v)
                if view.armed and view.state is SupervisorState.MANUAL:
                    self.armed_at_s.setdefault(v, now)
                    continue
                reason = arm_refusal(view, round_at[v])
                if reason and reason != reasons.get(v):
                    port.told(LaunchStage.ARM_REFUSED,
                              f"vehicle {v}: {reason}; asking again until {limit_s:g} s")
                reasons[v] = reason or reasons.get(v, "")
                end = since(view, round_at[v], ARM_FAILED)
                if end is not None:
                    failed[v] = end.note + vehicle_said(view)
            first = min(self.armed_at_s.values(), default=now)
            if len(self.armed_at_s) == len(self.stations) and now - first <= budget_s:
                port.told(LaunchStage.ARMED, f"all within {now - first:.1f} s of the first")
                return dict(self.armed_at_s)
            if failed or now >= deadline:
                self.disarm_all()
                raise LaunchFailed(self._why_not_armed(failed, reasons))
            if now - first > budget_s:
                self._stand_down(round_at, budget_s, deadline)
            port.idle()

    def _stand_down(self, round_at: dict[int, float], budget_s: float, deadline: float) -> None:
        """The first armed has stood `budget_s` while others are refused: disarm the armed
        ones before their firmware does, and ask them again with the rest."""
        port = self.port
        armed = sorted(self.armed_at_s)
        late = sorted(set(self.stations) - set(armed))
        port.told(LaunchStage.ARM_REFUSED,
                  f"vehicles {late} not armed within {budget_s:g} s of the first (the firmware "
                  f"disarms on the floor after {self.auto_disarm_s():g} s): vehicles {armed} "
                  "disarmed and asked again")
        for v in armed:
            st = self.stations[v]
            st.set_sticks(STICK_MID_US, STICK_MID_US, STICK_MID_US, STICK_MIN_US)
            st.request_disarm()
        # asked again once each is seen disarmed, so the new request does not meet the disarm
        give_up = port.now_s() + self.rules.mode_timeout_s
        while armed:
            for v in list(armed):
                if not port.look(v).armed:
                    armed.remove(v)
                    del self.armed_at_s[v]
                    round_at[v] = now = port.now_s()
                    self.stations[v].request_arm(
                        wait_s=max(deadline - now, 0.0) + ARM_ASK_GRACE_S)
            if armed and port.now_s() >= give_up:
                self.disarm_all()
                raise LaunchFailed(f"arming: vehicles {armed} did not disarm within "
                                   f"{self.rules.mode_timeout_s:g} s of the request; every "
                                   "vehicle asked to disarm")
            if armed:
                port.idle()

    def _why_not_armed(self, failed: dict[int, str], reasons: dict[int, str]) -> str:
        if failed:
            why = "; ".join(f"vehicle {v}: {note}" for v, note in sorted(failed.items()))
            return f"arming: {why}; every vehicle disarmed"
        late = sorted(set(self.stations) - set(self.armed_at_s))
        why = ", ".join(f"vehicle {v} ({reasons.get(v) or 'no reason given'})" for v in late)
        return (f"arming: not armed within {self.rules.arm_timeout_s:g} s of the request: "
                f"{why}; every vehicle disarmed")

    def disarm_all(self) -> None:
        """Disarm every vehicle on the floor (throttle minimum first)."""
        for st in self.stations.values():
            st.set_sticks(STICK_MID_US, STICK_MID_US, STICK_MID_US, STICK_MIN_US)
            st.request_disarm()
        self.port.told(LaunchStage.DISARMED, "")

    def ask_takeoff(self, alt_m: float, climb_mps: float) -> None:
        """Ask every armed vehicle to climb to `alt_m` at `climb_mps`; wait until each
        supervisor has taken the request (its spool-up or ramp under way). LaunchFailed when
        one refused it or did not take it in time."""
        port = self.port
        self.takeoff_asked_s = asked_at = port.now_s()
        for st in self.stations.values():
            st.alt_hold(True, alt_m, rate_mps=climb_mps)
        deadline = asked_at + TAKEOFF_ASK_S
        while True:
            waiting: list[int] = []
            for v in self.stations:
                view = port.look(v)
                refused = since(view, asked_at, frozenset({OutcomeKind.ALT_HOLD_REFUSED}))
                if refused is not None:
                    raise LaunchFailed(f"take-off: vehicle {v}: {refused.note}")
                if view.state is SupervisorState.MANUAL:
                    waiting.append(v)
            if not waiting:
                return
            if port.now_s() >= deadline:
                raise LaunchFailed(f"take-off: vehicles {waiting} did not take the request "
                                   f"within {TAKEOFF_ASK_S:g} s")
            port.idle()

    def check_climb(self, view: LaunchView, vehicle: int) -> None:
        """LaunchFailed when the supervisor gave up the vehicle's take-off ramp (it did not
        leave the floor at the ramp's top)."""
        if self.takeoff_asked_s is None:
            return
        failed = since(view, self.takeoff_asked_s, frozenset({OutcomeKind.TAKEOFF_FAILED}))
        if failed is not None:
            raise LaunchFailed(f"take-off: vehicle {vehicle}: {failed.note}")
