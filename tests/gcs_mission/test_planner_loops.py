"""The planner loops against the mission port, without a SITL: the kinematic world behind it,
with what a vehicle adds scripted on top (a move that does not settle, a vehicle taken off the
mission, a failsafe during a count)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from gcs.mission.events import EVENT, MissionEvent
from gcs.mission.kinematic import run_kinematic, start_of
from gcs.mission.kinematic_port import KinematicPort
from gcs.mission.loop_epbha import fly_epbha
from gcs.mission.loop_flock import fly_flock
from gcs.mission.loop_radiation import fly_radiation
from gcs.mission.planner_params import PlannerSetup, planner_setup
from gcs.mission.port import DetectorPort, ObstaclePort
from gcs.mission.recording import STEP_EPBHA, STEP_FLOCK, MissionRecording
from gcs.mission.report import MissionStatus
from gcs.mission.spec import MissionSpec, load_mission
from gcs.mission.world import MissionWorld, load_world
from planners.geometry import Vec3
from planners.kinematic import KinematicSim
from planners.proximity import ProximityParams

MISSIONS = Path(__file__).resolve().parents[2] / "missions"


class Tape:
    """A recorder that keeps every message."""

    path = None

    def __init__(self) -> None:
        self.messages: list[tuple[str, float, Any]] = []

    def put(self, topic: str, t_s: float, payload: Any) -> None:
        self.messages.append((topic, t_s, payload))

    def topic(self, topic: str) -> list[Any]:
        return [m for name, _, m in self.messages if name == topic]


def _load(name: str) -> tuple[MissionSpec, MissionWorld, PlannerSetup]:
    spec = load_mission(MISSIONS / f"{name}.toml")
    mw = load_world(spec.world_path)  # type: ignore[arg-type]
    return spec, mw, planner_setup(spec, mw.world.room.min_n[:2], mw.world.room.max_n[:2])


class Unsettled(KinematicPort):
    """Every move ends 3 cm short to the east, as a vehicle that timed out before settling."""

    def go(self, targets_n: dict[int, Vec3], timeout_s: float | None = None) -> dict[int, Vec3]:
        short = {v: (t[0], t[1] - 0.03, t[2]) for v, t in targets_n.items()}
        super().go(short, timeout_s)
        return {v: self.position_n(v) for v in targets_n}


class LinkLost(KinematicPort):
    """Vehicle `who` is taken off the mission once the team has made `after` moves."""

    after = 3
    who = 1
    moves = 0

    def go(self, targets_n: dict[int, Vec3], timeout_s: float | None = None) -> dict[int, Vec3]:
        self.moves += 1
        return super().go(targets_n, timeout_s)

    def check(self) -> dict[int, str]:
        return {self.who: "link lost"} if self.moves >= self.after else {}


class FailsafeLand(KinematicPort):
    """A battery failsafe takes the vehicle during its third count."""

    counts = 0

    def off_mission(self, vehicle: int) -> str | None:
        self.counts += 1
        return "mode LAND (battery)" if self.counts >= 3 else None


def _epbha_port(cls: type[KinematicPort], tape: Tape) -> tuple[ObstaclePort, Vec3, PlannerSetup]:
    spec, mw, setup = _load("epbha_table")
    s = start_of(spec, mw, 0)
    start = (s[0], s[1], -spec.takeoff_alt_m)
    prox = ProximityParams(range_m=setup.params.sensor_range_m,
                           cone_deg=setup.params.sensor_cone_deg)
    sim = KinematicSim(mw.world, start, proximity=prox, rng=np.random.default_rng(3))
    port = cls(spec, MissionRecording(tape), {1: sim}, 0.0, step_s=0.2)
    return port, start, setup


def test_the_kinematic_port_runs_epbha_to_the_goal_on_its_nominal_timeline() -> None:
    tape = Tape()
    port, start, setup = _epbha_port(KinematicPort, tape)
    out = fly_epbha(port, setup, start)
    assert out.status is MissionStatus.REACHED and out.loop == "epbha"
    steps = tape.topic(STEP_EPBHA)
    assert len(steps) == out.steps + 1
    assert port.elapsed_s() == 0.2 * out.steps
    assert all(s["pos"] == s["measured"] for s in steps)  # exact moves


def test_a_move_that_did_not_settle_gives_the_planner_the_measured_position() -> None:
    tape = Tape()
    port, start, setup = _epbha_port(Unsettled, tape)
    fly_epbha(port, setup, start)
    steps = tape.topic(STEP_EPBHA)
    assert len(steps) > 2
    for s in steps[1:]:
        assert s["pos"] == s["measured"]
        assert s["pos"]["y"] != 0.0  # 3 cm off the set positions along y = 0


def test_a_vehicle_taken_off_the_mission_ends_the_loop_with_its_reason() -> None:
    tape = Tape()
    port, start, setup = _epbha_port(LinkLost, tape)
    out = fly_epbha(port, setup, start)
    assert out.status is MissionStatus.FAILED and out.reason == "vehicle 1: link lost"
    assert out.steps == LinkLost.after and len(tape.topic(STEP_EPBHA)) == LinkLost.after + 1


def test_a_failsafe_during_a_count_drops_the_sample_and_ends_the_mapping() -> None:
    spec, mw, setup = _load("radiation_3src")
    xy = setup.params.clip(np.asarray(start_of(spec, mw, 0)[:2], dtype=float))
    start = (float(xy[0]), float(xy[1]), -spec.takeoff_alt_m)
    tape = Tape()
    port: DetectorPort = FailsafeLand(
        spec, MissionRecording(tape), {1: KinematicSim(mw.world, start)}, 0.0,
        field=mw.radiation_field(height_m=spec.takeoff_alt_m), rng=np.random.default_rng(3))
    out = fly_radiation(port, setup, start, None)
    assert out.status is MissionStatus.FAILED and out.loop == "radiation"
    assert out.reason == "mode LAND (battery) at sample 2"
    events = tape.topic(EVENT)
    assert [e["event"] for e in events] == [MissionEvent.SAMPLE_DROPPED.value]
    assert out.steps == 2 and len(out.path_n) == 3


def test_the_flock_loop_brings_the_team_home_and_stops_for_a_lost_teammate() -> None:
    spec, mw, setup = _load("flock_table")
    home, _ = run_kinematic(spec, mw, setup, MissionRecording(None), None)
    assert home.reached and home.metrics["planner_loop"] == "flock"
    assert home.duration_s == 0.2 * home.steps
    ids = [v.sysid for v in spec.vehicles]
    starts = {v: (float(v), 0.0, -1.0) for v in ids}  # a row 1 m apart, clear of the boxes
    tape = Tape()
    port = LinkLost(spec, MissionRecording(tape),
                    {v: KinematicSim(mw.world, p) for v, p in starts.items()}, 0.0, step_s=0.2)
    port.who, port.after = 3, 10
    out = fly_flock(port, setup, starts)
    assert out.status is MissionStatus.FAILED and out.reason == "vehicle 3: link lost"
    assert out.steps == 10 and len(tape.topic(STEP_FLOCK)) == 11
    assert out.metrics["min_separation_m"] <= 1.0
