"""The flight core: estimator, controllers and supervisor stepped on one tick's inputs.

No I/O, no clock, no threads: time comes in with the inputs (`t_s`, `dt_s`), so the station
flying a vehicle and a rerun of its recording run the same steps on the same inputs and get the
same outputs.
"""

from __future__ import annotations

from firmware_link.records import Attitude, Dialect, MocapPose
from gcs.config import HoldMode, StationConfig
from gcs.control.altitude_controller import AltitudeController
from gcs.control.climb_rate_hold import ClimbRateHold
from gcs.control.climb_stick import ClimbStickMap
from gcs.control.position_controller import PositionController
from gcs.control.throttle_curve import CurveKind, ThrottleCurve
from gcs.core.inputs import TickInputs
from gcs.core.landing import lands_on_death, may_leave, must_land
from gcs.core.link_down import LinkDownClock
from gcs.core.outputs import TickOutputs
from gcs.estimation import AltEstimator, baro_altitude_m, make_estimator
from gcs.supervisor import Supervisor, SupervisorParams, SupervisorState, TickIn, VehicleStatus


def at_rest(vehicle: VehicleStatus, lost_after_s: float) -> bool:
    """Disarmed, the motors are stopped: the vehicle stands still (the estimator checks it is
    on the floor). Before the first heartbeat, or with the link silent, nothing is known."""
    return vehicle.seen and not vehicle.armed and vehicle.frame_age_s <= lost_after_s


class FlightCore:
    """Owns the estimator, the controllers, the supervisor and the station's tick rules."""

    def __init__(self, config: StationConfig, curve: ThrottleCurve,
                 hover_throttle: float | None, supervisor: SupervisorParams,
                 climb_stick: ClimbStickMap | None = None) -> None:
        """`climb_stick`: the vehicle's ALT_HOLD stick map, for the climb-rate hold (None:
        the firmware's defaults for the curve's dialect)."""
        self.config = config
        self.params = supervisor
        self.estimator: AltEstimator = make_estimator(config.estimator_kind.value,
                                                      config.estimator)
        self.alt_ctrl = AltitudeController(config.altitude, curve, hover_throttle)
        self.pos_ctrl = PositionController(config.position)
        est = config.estimator
        climb = None
        if config.hold_mode is HoldMode.CLIMB_RATE:
            dialect = Dialect.COPTER4 if curve.kind is CurveKind.COPTER4 else Dialect.APM25
            climb = ClimbRateHold(config.climb,
                                  climb_stick or ClimbStickMap.for_dialect(dialect))
        # the sonar reads from sonar_min_m below it, so the estimate has it from here up
        blind_top_m = est.sonar_min_m + est.sonar_offset_m
        self.supervisor = Supervisor(
            supervisor, self.alt_ctrl, self.pos_ctrl, rest_alt_m=est.rest_alt_m,
            ground_alt_m=est.ground_alt_m, hold_floor_m=blind_top_m + supervisor.blind_margin_m,
            takeoff_alt_m=config.flight.takeoff_alt_m,
            takeoff_climb_mps=config.flight.takeoff_climb_mps, climb=climb)
        self.link_down = LinkDownClock()
        self.last: TickOutputs | None = None
        # the newest attitude and pose of any tick: the supervisor flies on them until others come
        self._attitude: Attitude | None = None
        self._pose: MocapPose | None = None

    @property
    def state(self) -> SupervisorState:
        return self.supervisor.state

    @property
    def must_land(self) -> bool:
        """Stopping now, the station lands the vehicle before letting go."""
        return must_land(self.supervisor.state)

    @property
    def may_leave(self) -> bool:
        """A stopping station's landing is done."""
        return may_leave(self.supervisor.state)

    @property
    def lands_on_death(self) -> bool:
        """A loop dying now asks the vehicle for LAND on its way out."""
        return lands_on_death(self.supervisor.state)

    def step(self, inputs: TickInputs) -> TickOutputs:
        """One tick: estimate, decide, count."""
        if inputs.attitudes:
            self._attitude = inputs.attitudes[-1]
        if inputs.mocaps:
            self._pose = inputs.mocaps[-1]
        rest = at_rest(inputs.vehicle, self.params.lost_after_s)
        last = self.last
        est = self.estimator.update_tick(
            list(inputs.imus), inputs.sonars,
            inputs.attitudes[-1] if inputs.attitudes else None, inputs.t_s, at_rest=rest,
            baro_alt_m=baro_altitude_m(inputs.baros[-1].pressure_pa) if inputs.baros else None,
            command_acc_mps2=last.supervisor.command_acc_mps2 if last is not None else None,
            airborne=self.supervisor.flies_above_blind, liftoff=self.supervisor.liftoff_seed)
        self.supervisor.liftoff_seed = None
        att = self._attitude
        out = self.supervisor.step(TickIn(
            t_s=inputs.t_s, dt_s=inputs.dt_s, intents=inputs.intents, vehicle=inputs.vehicle,
            estimate=est, roll_rad=att.roll_rad if att is not None else 0.0,
            pitch_rad=att.pitch_rad if att is not None else 0.0, mocap=self._pose))
        down = self.link_down.update(out.link, inputs.vehicle.frame_age_s, inputs.dt_s)
        self.last = TickOutputs(est, out, self.supervisor.alt, self.supervisor.position, rest,
                                down)
        return self.last
