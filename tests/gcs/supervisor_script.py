"""A supervisor driven tick by tick with a scripted vehicle (the supervisor tests' rig)."""

from __future__ import annotations

from firmware_link.records import Dialect, FlightMode, MocapPose
from gcs.control.altitude_controller import AltitudeController, AltitudeControllerParams
from gcs.control.position_controller import PositionController, PositionControllerParams
from gcs.control.throttle_curve import ThrottleCurve
from gcs.estimation import AltEstimate, SonarStatus
from gcs.supervisor import (
    ActionKind,
    Intent,
    IntentKind,
    Supervisor,
    SupervisorOutput,
    SupervisorParams,
    TickIn,
    VehicleStatus,
)
from gcs.supervisor import SupervisorState as S

DT = 0.025
REST_M = 0.06



class Script:
    """Drives a supervisor tick by tick with a scripted vehicle."""

    def __init__(self, dialect: Dialect = Dialect.APM25, **params: object) -> None:
        self.sup = Supervisor(SupervisorParams.for_dialect(dialect, **params),
                              AltitudeController(AltitudeControllerParams(),
                                                 ThrottleCurve.for_dialect(dialect)),
                              PositionController(PositionControllerParams()),
                              rest_alt_m=REST_M, ground_alt_m=0.10)
        self.t = 100.0
        self.armed = False
        self.mode = int(FlightMode.STABILIZE)
        self.hb_t = self.t
        self.rx_t = self.t
        self.down = True  # the vehicle is heard
        self.alt = REST_M
        self.vel = 0.0
        self.acc = 0.0  # the estimate's bias-corrected upward acceleration
        self.mocap: MocapPose | None = None
        self.sonar = SonarStatus.USED  # what the estimator did with this tick's reading
        self.outs: list[SupervisorOutput] = []

    def tick(self, *intents: Intent) -> SupervisorOutput:
        self.t += DT
        if self.down:
            self.rx_t = self.t
            if self.t - self.hb_t >= 1.0:
                self.hb_t = self.t
        est = AltEstimate(self.t, self.alt, self.vel, self.acc, 0.0, True, self.sonar, 0.0, 0.0,
                          False, 0.01, 0)
        v = VehicleStatus(seen=True, armed=self.armed, mode=self.mode, heartbeat_t_s=self.hb_t,
                          frame_age_s=self.t - self.rx_t)
        out = self.sup.step(TickIn(self.t, DT, intents, v, est, 0.0, 0.0, self.mocap))
        self.outs.append(out)
        return out

    def run(self, seconds: float) -> list[SupervisorOutput]:
        n = round(seconds / DT)
        return [self.tick() for _ in range(n)]

    def heartbeat_now(self) -> None:
        self.hb_t = self.t + DT  # the next tick carries a fresh heartbeat

    def armed_in_stabilize(self) -> None:
        self.tick(Intent(IntentKind.PREFLIGHT, ok=True, note="test"))
        out = self.tick(Intent(IntentKind.ARM))
        assert any(a.kind is ActionKind.ARM for a in out.actions)
        self.armed = True
        self.heartbeat_now()
        self.tick()
        assert self.sup.state is S.MANUAL

    def hovering(self, alt_m: float = 1.0) -> None:
        """Armed, in HOLD at alt_m (the vehicle follows perfectly)."""
        self.armed_in_stabilize()
        self.alt = alt_m
        self.tick(Intent(IntentKind.ALT_HOLD, setpoint_m=alt_m))
        assert self.sup.state is S.HOLD


def actions(outs: list[SupervisorOutput], kind: ActionKind) -> list[int | None]:
    """Per tick that sent a `kind`, the mode of its first one."""
    return [next(a.mode for a in o.actions if a.kind is kind)
            for o in outs if any(a.kind is kind for a in o.actions)]
