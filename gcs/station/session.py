"""Bring a station up against a vehicle (or the bundled SITL) and take it down again.

Every command that flies (`fly`, `teleop`, `mission run`) needs the same steps: start the SITL
when no `--connect` is given, open a recorder per vehicle, open the link with the raw tap on the
recorder, bring the telemetry streams up, read the throttle-curve parameters, open motion capture
and build a `Station`. `StationSession` does them in order and undoes them in reverse, whatever
happens in between: overrides released, links closed, files finished, the SITL stopped.
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from firmware_link import (
    DEFAULT_CONNECT_TIMEOUT_S,
    Forwarder,
    MocapLink,
    ParamError,
    VehicleLink,
    open_when_up,
)
from firmware_link.records import Battery, Dialect, GpsFix, MocapPose
from firmware_link.truth_link import TruthLink, TruthRecorder
from gcs.clock import Clock, MonotonicClock, ScaledClock
from gcs.config import HoldMode, StationConfig, load_config
from gcs.control.climb_stick import CLIMB_PARAMS, ClimbStickMap
from gcs.control.position_controller import STICK_PARAMS, with_vehicle_sticks
from gcs.control.throttle_curve import ThrottleCurve
from gcs.errors import UsageError
from gcs.failsafe_policy import VehicleState
from gcs.foxglove_feed import DEFAULT_WORLD, FoxgloveFeed, open_live, world_boxes
from gcs.parallel_open import open_in_parallel
from gcs.preflight import PreflightReport, read_and_check
from gcs.scoring import Series, station_time
from gcs.sitl_process import SitlEndpoints, SitlOptions, SitlProcess
from gcs.station.guardian import Guardian, GuardianSetup
from gcs.station.rangefinder import vehicle_rangefinder
from gcs.station.station import Station
from gcs.station.types import clock_speedup
from gcs.toml_file import read_signing_key

if TYPE_CHECKING:  # the recorder's module is imported only when a recording is asked for
    from logs import Recorder
    from logs.live import LiveView

CURVE_PARAMS = {Dialect.APM25: ("THR_MIN", "THR_MID"), Dialect.COPTER4: ("MOT_THST_HOVER",)}
STREAM_RATE_HZ = 40.0
# commands that score a flight get the bundled SITL's ground-truth endpoint (gcs.scoring)
SCORED_COMMANDS = frozenset({"fly"})


@dataclass(frozen=True, slots=True)
class SessionOptions:
    """What to connect to and how; the CLI fills it from its flags."""

    command: str
    connect: str | None = None  # None: start the bundled SITL
    mocap: str | None = None
    profile: str = "apm25"
    world: Path | None = None
    serial: bool = False
    speedup: float = 1.0
    seed: int | None = None
    config: Path | None = None
    signing_key: Path | None = None
    record: bool = True
    output: Path = Path("flights")
    sysids: tuple[int, ...] = (1,)
    # The loop's clock spins the last stretch before a tick for precision, holding the GIL;
    # a UI in the same process wants it back, so teleop trades a little jitter for it.
    spin_s: float = 0.0015
    metadata: dict[str, Any] = field(default_factory=dict)
    fix_failsafe: bool = False  # the pilot's consent to set unsafe failsafe parameters
    foxglove: str | None = None  # [HOST:]PORT: serve the flight live to Foxglove
    forward: tuple[str, ...] = ()  # other ground stations' URLs (firmware_link.forward)
    # how long `connect` is waited for when it is not up yet (firmware_link.wait_up)
    connect_timeout_s: float = DEFAULT_CONNECT_TIMEOUT_S
    # where a hold asked on the floor with no altitude climbs to (None: the config's, 1.0 m)
    takeoff_alt_m: float | None = None

    def validate(self) -> None:
        """Reject impossible combinations with one line each."""
        if not 0 < self.speedup <= 50:
            raise UsageError(f"--speedup {self.speedup}: expected 0 < speedup <= 50")
        if self.world is not None and not self.world.is_file():
            raise UsageError(f"--world {self.world}: no such file")
        if self.connect is not None and len(self.sysids) > 1:
            raise UsageError("--connect flies one vehicle; several need the bundled SITL")


def _tell(line: str) -> None:
    """A waiting line for the pilot (before any screen is up)."""
    print(line, file=sys.stderr, flush=True)


class MocapFor:
    """One vehicle's view of a motion-capture stream that tracks several bodies."""

    def __init__(self, link: MocapLink, sysid: int) -> None:
        self.link = link
        self.sysid = sysid

    def poll(self) -> list[MocapPose]:
        """Poses of this vehicle only."""
        return [p for p in self.link.poll() if p.sysid == self.sysid]


@dataclass(slots=True)
class Vehicle:
    """One connected vehicle: its link, station and recorder."""

    sysid: int
    url: str
    link: VehicleLink
    station: Station
    recorder: Recorder | None
    # what the station records into: the recorder plus the 3D view's topics and the live view
    sink: FoxgloveFeed | None = None
    # the bundled SITL's ground truth, for scoring only: nothing that flies reads it
    truth: TruthRecorder | None = None

    def truth_series(self) -> Series | None:
        """The truth endpoint's reports so far as altitudes above the floor on the station's
        clock; None without the endpoint (a score then uses the link's SIM_STATE, if any)."""
        reports = self.truth.reports() if self.truth is not None else []
        if not reports:
            return None
        return station_time([r.rx_s for r in reports], [r.t_s for r in reports],
                            [r.alt_m for r in reports])


class StationSession:
    """Context manager: the vehicles' stations, built but not started."""

    # UTC nanoseconds at the clock's zero in recordings; None: the monotonic clock's zero
    recording_anchor_ns: int | None = None
    # a recorder that cannot keep up makes the station wait (simulated time) instead of dropping
    recording_blocks = False

    def __init__(self, options: SessionOptions, *, config: StationConfig | None = None) -> None:
        """`config`: the stations' configuration (None: `options.config`'s file, or defaults)."""
        options.validate()
        self.options = options
        self.station_config = config
        self.clock: Clock = (
            MonotonicClock(options.spin_s) if options.speedup == 1.0
            else ScaledClock(options.speedup, options.spin_s)
        )
        self.vehicles: dict[int, Vehicle] = {}
        self.sitl_endpoints: SitlEndpoints | None = None  # the bundled SITL's, when started
        self.preflight: dict[int, PreflightReport] = {}
        self.live: LiveView | None = None  # with --foxglove
        self.forwarder: Forwarder | None = None
        self._stack = contextlib.ExitStack()

    def __enter__(self) -> StationSession:
        try:
            self._open()
        except BaseException:
            self._stack.close()
            raise
        return self

    def __exit__(self, *exc: object) -> None:
        self._stack.close()

    def _preflight(self, link: VehicleLink, wait_s: float = 2.0) -> PreflightReport:
        """Read the failsafe, radio and battery facts and the GPS fix, and judge them (setting
        the failsafe parameters with the pilot's consent). A GPS the vehicle did not report
        within `wait_s` is judged at its worst (a fix: RTL navigates)."""
        battery_v: float | None = None
        fix_type: int | None = None
        deadline = self.clock.now_s() + wait_s
        while (battery_v is None or fix_type is None) and self.clock.now_s() < deadline:
            for r in link.poll():
                if isinstance(r, Battery) and r.voltage_v > 0.0:
                    battery_v = r.voltage_v
                elif isinstance(r, GpsFix):
                    fix_type = r.fix_type
            if battery_v is None or fix_type is None:
                self.clock.sleep_until(self.clock.now_s() + 0.05)
        report = read_and_check(link.get_param, link.set_param, link.dialect, battery_v,
                                fix=self.options.fix_failsafe,
                                state=VehicleState(gps_fix_type=fix_type))
        line = report.fix_line()
        if line is not None:
            print(f"vehicle {link.target_system}: {line}", file=sys.stderr, flush=True)
        return report

    @staticmethod
    def _vehicle_sticks(link: VehicleLink, config: StationConfig) -> StationConfig:
        """The position loop's stick mapping as the vehicle has it (ANGLE_MAX, RC1/2_DZ)."""
        try:
            values = link.read_params(STICK_PARAMS)
            position = with_vehicle_sticks(config.position, values)
        except ParamError as exc:
            raise ParamError(f"{exc} (the position hold needs {', '.join(exc.names)})",
                             exc.names) from None
        except ValueError as exc:
            raise ParamError(str(exc), STICK_PARAMS) from None
        return dataclasses.replace(config, position=position)

    @property
    def first(self) -> Vehicle:
        """The vehicle of a single-vehicle session."""
        return self.vehicles[self.options.sysids[0]]

    def _key(self) -> bytes | None:
        return read_signing_key(self.options.signing_key)

    def _open(self) -> None:
        o = self.options
        key = self._key()
        config = self.station_config if self.station_config is not None else load_config(o.config)
        urls: dict[int, str] = {}
        mocap_url = o.mocap
        if o.connect is None:
            sitl = SitlProcess(SitlOptions(profile=o.profile, world=o.world,
                                           vehicles=max(o.sysids), speedup=o.speedup,
                                           serial=o.serial, seed=o.seed,
                                           signing_key=o.signing_key,
                                           truth=o.command in SCORED_COMMANDS))
            self.sitl_endpoints = sitl.start()
            self._stack.callback(sitl.stop)
            urls = {s: self.sitl_endpoints.url(s, serial=o.serial) for s in o.sysids}
            mocap_url = mocap_url or self.sitl_endpoints.mocap
        else:
            urls = {o.sysids[0]: o.connect}
        if o.foxglove is not None:
            self.live = open_live(o.foxglove)
            self._stack.callback(self.live.close)
            # before any screen is up (teleop's starts once the session is ready)
            print(f"foxglove: live view on {self.live.url}", file=sys.stderr, flush=True)
        if o.forward:
            self.forwarder = Forwarder.open(o.forward)
            self._stack.callback(self.forwarder.close)
            print(f"forward: {', '.join(self.forwarder.urls)}", file=sys.stderr, flush=True)
        # a vehicle's bring-up waits seconds on the vehicle: every vehicle's at once
        self.vehicles.update(open_in_parallel(
            {sysid: functools.partial(self._open_vehicle, sysid, url, mocap_url, key, config)
             for sysid, url in urls.items()}, self._stack))
        truth_url = self.sitl_endpoints.truth if self.sitl_endpoints is not None else None
        if truth_url is not None:
            for sysid, v in self.vehicles.items():
                v.truth = TruthRecorder(TruthLink.open(truth_url, clock=self.clock.now_s), sysid)
                self._stack.callback(v.truth.close)

    def _open_vehicle(self, sysid: int, url: str, mocap_url: str | None, key: bytes | None,
                      config: StationConfig, stack: contextlib.ExitStack | None = None) -> Vehicle:
        """One vehicle (on its own thread, see `_open`): what it opens is undone through
        `stack` (default: the session's)."""
        stack = self._stack if stack is None else stack
        o = self.options
        recorder = None
        if o.record:
            from logs import Recorder, RecordingError

            meta = {"command": o.command, "url": url, "vehicle": str(sysid),
                    "profile": o.profile, **{k: str(v) for k, v in o.metadata.items()}}
            try:
                recorder = Recorder(o.output, metadata=meta, vehicle=f"vehicle{sysid}",
                                    anchor_ns=self.recording_anchor_ns,
                                    block_when_full=self.recording_blocks)
            except RecordingError as exc:
                raise UsageError(f"-o {o.output}: {exc}") from None
            stack.callback(recorder.close)
        sink = None
        if recorder is not None or self.live is not None:
            world = o.world if o.world is not None or o.connect is not None else DEFAULT_WORLD
            sink = FoxgloveFeed(recorder, self.live, sysid=sysid, boxes=world_boxes(world),
                                live_prefix=f"/v{sysid}" if len(o.sysids) > 1 else "")
        # one vehicle takes every forwarded frame; several share them out by target system
        forward = (self.forwarder.port(sysid if len(o.sysids) > 1 else None)
                   if self.forwarder is not None else None)
        on_raw = sink.put_raw if sink is not None else None
        if o.connect is None:  # the bundled SITL is up: its ports are open
            link = VehicleLink.open(url, signing_key=key, clock=self.clock.now_s,
                                    target_system=sysid, on_raw=on_raw, forward=forward)
        else:  # a vehicle may still be booting: wait for it as other ground stations do
            link = open_when_up(url, timeout_s=o.connect_timeout_s, on_wait=_tell,
                                clock=self.clock.now_s, signing_key=key, on_raw=on_raw,
                                forward=forward)
        stack.callback(link.close)
        link.bring_up(STREAM_RATE_HZ)
        # The throttle curve is how the station turns a thrust into a stick: a default in place
        # of the vehicle's own value would fly a wrong curve, so a failed read stops here.
        names = CURVE_PARAMS.get(link.dialect, ())
        climbing = config.hold_mode is HoldMode.CLIMB_RATE
        if climbing:  # and the climb-rate hold's stick is ALT_HOLD's, with its parameters
            names = (*names, *CLIMB_PARAMS.get(link.dialect, ()))
        try:
            params = link.read_params(names)
        except ParamError as exc:
            raise ParamError(f"{exc} (the throttle curve and the hold's stick need "
                             f"{', '.join(exc.names)})",
                             exc.names) from None
        curve = ThrottleCurve.for_dialect(link.dialect, params)
        # the sonar's blind band and steps as the vehicle's driver has them (default 20 cm)
        estimator, _ = vehicle_rangefinder(config.estimator, link.dialect, link.read_params)
        config = dataclasses.replace(config, estimator=estimator)
        if o.takeoff_alt_m is not None:
            config = dataclasses.replace(config, flight=dataclasses.replace(
                config.flight, takeoff_alt_m=o.takeoff_alt_m))
        climb_stick = ClimbStickMap.for_dialect(link.dialect, params) if climbing else None
        if mocap_url is not None:
            config = self._vehicle_sticks(link, config)
        mocap = None
        if mocap_url is not None:
            mocap_link = MocapLink.open(mocap_url, clock=self.clock.now_s)
            stack.callback(mocap_link.close)
            mocap = MocapFor(mocap_link, sysid)
        station = Station(link, config=config, curve=curve, mocap=mocap, recorder=sink,
                          clock=self.clock, climb_stick=climb_stick)
        guardian = Guardian.start(link, GuardianSetup(
            link.spec, link.firmware, link.target_system, link.target_component, key,
            config.period_s, clock_speedup(self.clock)))
        if guardian is not None:
            station.add_listener(guardian.on_snapshot)
            # after the station's own landing and letting go, before the link closes: a
            # TCP link ends only when the guardian's copy of it is closed too
            stack.callback(guardian.stand_down)
        report = self._preflight(link)
        self.preflight[sysid] = report
        station.preflight(report.ok, report.summary())
        # registered last, so it stops first: the loop releases overrides before links close
        stack.callback(station.stop)
        return Vehicle(sysid=sysid, url=url, link=link, station=station, recorder=recorder,
                       sink=sink)
