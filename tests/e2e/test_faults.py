"""`quadgcs fly` through a fault injector: the link dies one way, both ways, or turns lossy.

Each flight: the SITL (its own program), the fault proxy between it and the station, and the
real CLI `quadgcs fly --connect <proxy> --mocap <sitl mocap> --json`, holding 1.0 m. Twenty
seconds into the hold the fault starts (bench/faults.py: thirty, as the issue measured; the
hold has settled long before either, and the matrix's wall time is the suite's longest).
Height is judged from motion capture, which the fault does not touch; the vehicle's arming
state, mode and failsafe texts from a UDP endpoint of the SITL that only listens.

What the station's policy promises: proof of life is any frame; a short gap holds a safe
command; a gap over ~1 s makes it request LAND, with heartbeats, until the vehicle is heard
again (its throttle at minimum once that LAND has had time to touch down, so 3.2.1 disarms; the
autopilot's own failsafe acts if the uplink is dead too; `fly` lets go after its quit timeout);
nothing resumes when the link returns. So for a lost link, one way or both: never above setpoint
+ 0.3 m, touchdown no faster than 1.0 m/s, on the floor and disarmed within 20 s of the fault
(where the uplink is dead, plus the descent at the firmware's LAND speed from any height the
open-loop seconds climbed past the bound: in lockstep, apm25 fades that reached the ceiling
disarmed 16.3 and 16.6 s after the fault, against 9.3-13.9 s for the other 58 of 60;
bench/open_loop.py), `fly` exits 3 with a reason line, and a station that cannot see the vehicle
asks for LAND more than once (what it sent is read off the uplink by a tap in the proxy, whether
the frames got through or not). With 30 % loss and 5 % bit flips it keeps holding within ±0.1 m
and exits 0.

The matrix is flown once per session (a module fixture, only the selected cases), in real time
three flights at a time, or QUADGCS_FAULT_SPEEDUP=K times faster (tests/e2e/fault_flight.py).
"""

from __future__ import annotations

import pytest

from sitl.fault_frames import Direction
from tests.e2e.fault_flight import CASES, FlightResult, FlightSpec, run_many

pytestmark = [pytest.mark.e2e, pytest.mark.wallclock, pytest.mark.timeout(900)]

MATRIX = [
    *(FlightSpec(case, profile) for case in ("downlink", "uplink", "both")
      for profile in ("apm25", "copter4")),
    # the 100 s lossy flight once, on the MAVLink 1 board (bench/faults.py flies both), to stay
    # within five minutes of wall time
    FlightSpec("lossy", "apm25"),
    # the product's own case: an APM 2.5 on its 115200-baud radio, out of range
    FlightSpec("both", "apm25", "serial"),
]
AFTER_HOLD_S = 20.0
MAX_OVER_SETPOINT_M = 0.3
ROSE = "rose "  # the start of the problem line for a vehicle above that
SANK = "touched down at "  # ...and for one that met the floor too fast
MAX_TOUCHDOWN_MPS = 1.0
DOWN_AND_DISARMED_S = 20.0
# Both firmwares' LAND descends at LAND_SPEED, 50 cm/s by default: a vehicle the open-loop
# seconds carried past the bound (reported, below) has that much further to come down before
# its land detector can disarm it
FIRMWARE_LAND_MPS = 0.5
LOSSY_HOLD_M = 0.1
# The hold before the fault must be a hold (the station's own tests fly it to a few cm RMS):
# worse means the machine could not keep up with the run, and the fault tells nothing.
PRE_FAULT_RMS_M = 0.05
FLIGHT_FAILED_EXIT = 3
MIN_LAND_REQUESTS = 2  # "requests LAND (SET_MODE, repeated) for a few seconds"


@pytest.fixture(scope="module")
def flights(request: pytest.FixtureRequest) -> dict[FlightSpec, FlightResult | Exception]:
    """Every selected flight of this module, flown together."""
    wanted = [spec for item in request.session.items
              if isinstance(item, pytest.Function) and item.module is request.module
              and hasattr(item, "callspec")
              and isinstance(spec := item.callspec.params["spec"], FlightSpec)]
    return run_many(wanted, after_hold_s=AFTER_HOLD_S)


def _problems(r: FlightResult) -> list[str]:
    c = r.case
    out: list[str] = []
    if r.fault_start_s is None:
        return [f"the fault never started (fly ended first: exit {r.exit_code}, {r.reason!r})"]
    pre = r.pre_fault_rms_m
    if pre is None or not pre <= PRE_FAULT_RMS_M:
        out.append(f"the hold before the fault was already off (RMS {pre} m over 10 s): an "
                   "overloaded machine or a station that cannot hold")
    if not r.max_over_setpoint_m <= MAX_OVER_SETPOINT_M:
        out.append(f"{ROSE}{r.max_over_setpoint_m:.2f} m over the setpoint")
    if c.lands:
        limit_s = DOWN_AND_DISARMED_S
        if c.direction is not Direction.DOWN:  # the firmware's failsafe flies the landing
            limit_s += max(r.max_over_setpoint_m - MAX_OVER_SETPOINT_M, 0.0) / FIRMWARE_LAND_MPS
        down = r.touchdown_s
        if down is None or down - r.fault_start_s > limit_s:
            out.append(f"not on the floor within {limit_s:.1f} s of the fault")
        speed = r.touchdown_speed_mps
        if speed is not None and not speed <= MAX_TOUCHDOWN_MPS:
            out.append(f"{SANK}{speed:.2f} m/s")
        off = r.disarm_s
        if off is None or off - r.fault_start_s > limit_s:
            out.append(f"not disarmed within {limit_s:.1f} s of the fault")
        if r.exit_code != FLIGHT_FAILED_EXIT or not r.reason.startswith("quadgcs fly: "):
            out.append(f"fly exited {r.exit_code} with {r.reason!r}, expected "
                       f"{FLIGHT_FAILED_EXIT} and a reason line")
        if c.direction is not Direction.DOWN and r.land_mode_s is None and not r.failsafe_texts:
            out.append("the vehicle's own failsafe never acted (no LAND, no failsafe text)")
        sent = r.station_after_fault or {}
        lands = sent.get("land_requests_s", [])
        if c.direction is not Direction.UP and len(lands) < MIN_LAND_REQUESTS:
            # blind, the station cannot know whether one SET_MODE arrived: it must repeat it
            out.append(f"the blind station asked for LAND {len(lands)} time(s) "
                       f"(at {lands} s after the fault), not repeatedly; its last frame at "
                       f"{sent.get('last_frame_s')} s, overrides released at "
                       f"{sent.get('released_s')} s")
    else:
        dev = r.hold_during_fault_m
        if dev is None or not dev <= LOSSY_HOLD_M:
            out.append(f"held only within ±{dev if dev is None else round(dev, 3)} m")
        if r.exit_code != 0:
            out.append(f"fly exited {r.exit_code} with {r.reason!r} on a flight that went as "
                       "commanded")
        if not (r.up.frames_corrupted and r.down.frames_corrupted and r.down.frames_dropped):
            out.append("the proxy never lost or corrupted a frame: no fault was tested")
    return out


OPEN_LOOP = ("with the uplink dead ArduCopter 3.2.1 flies the last override for about 2 s until "
             "its radio failsafe; the station bounds how far down that command may push "
             "(gcs/supervisor/envelope.py) but not how far up, and the hold's throttle swings "
             "about ±30 us, so the climb in those seconds can cross setpoint + 0.3 m "
             "(bench/open_loop.py, 60 lockstep seeds: 23 rose over +0.3 m). Nothing the station "
             "sends arrives then, so the issue asks this drift measured and reported, as here")
OPEN_LOOP_4X = ("with the uplink dead ArduCopter 4.x flies the last override for 2 s "
                "(FS_GCS_TIMEOUT 2, its minimum) until its GCS failsafe lands it; the climb in "
                "those seconds is not bounded and can cross setpoint + 0.3 m "
                "(bench/open_loop.py, 60 lockstep seeds: 20 rose over +0.3 m). Nothing the "
                "station sends arrives then, so the issue asks this drift measured and "
                "reported, as here")
# The one property of a case the station cannot hold and the suite reports (the starts of its
# problem lines) and why; everything else the case promises (the landing, the disarm, the
# touchdown speed, the exit code, LAND asked) stays strict. The open-loop seconds may climb past
# the setpoint; the blind-flight envelope keeps them off the floor (60 lockstep seeds: touchdown
# 0.88 m/s at worst; bench/blind_risk.py: no tick of a steady hold over 1.0 m/s by truth), and
# the 1.0 m/s is not a drift to report. The lossy case is strict: bench/lossy_hold.py,
# 60 lockstep seeds, worst 9.0 cm on apm25 and 8.9 cm on copter4.
REPORTED = {
    "uplink-apm25-tcp": ((ROSE,), OPEN_LOOP),
    "both-apm25-tcp": ((ROSE,), OPEN_LOOP),
    "uplink-copter4-tcp": ((ROSE,), OPEN_LOOP_4X),
    "both-copter4-tcp": ((ROSE,), OPEN_LOOP_4X),
    # the same seconds over the 115200-baud line (rose 0.99 m once, from 29 us over the median)
    "both-apm25-serial": ((ROSE,), OPEN_LOOP),
}


# The apm25 cases: the SITL's 3.2.1 rangefinder is the real analog sonar (6 cm steps). The
# hold before the fault now meets the 5 cm these flights require (lockstep median 2.0 cm, and
# the lossy and serial cases pass), but the direct-throttle hold is not safe blind on 3.2.1's
# 5 s GCS timeout (bench/fault_suite.py: up to 3.6 m over the hold). Not strict: wall clock.
SONAR_STEPS_3_2_1 = ("#32: the direct-throttle hold flies its last override blind for 3.2.1's "
                     "5 s GCS timeout (bench/fault_suite.py: up to 3.6 m over the hold; the "
                     "climb-rate hold, not yet the default, stays within 0.32 m)")
UNSAFE_ON_THE_REAL_FIRMWARE = {
    "downlink-apm25-tcp": SONAR_STEPS_3_2_1,
    "uplink-apm25-tcp": SONAR_STEPS_3_2_1,
    "both-apm25-tcp": SONAR_STEPS_3_2_1,
    "lossy-apm25-tcp": SONAR_STEPS_3_2_1,
    "both-apm25-serial": SONAR_STEPS_3_2_1,
}


def _param(spec: FlightSpec) -> object:
    why = UNSAFE_ON_THE_REAL_FIRMWARE.get(spec.id)
    marks = [pytest.mark.xfail(strict=False, reason=why)] if why else []
    return pytest.param(spec, id=spec.id, marks=marks)


@pytest.mark.parametrize("spec", [_param(s) for s in MATRIX])
def test_station_survives_the_fault(
        spec: FlightSpec, flights: dict[FlightSpec, FlightResult | Exception]) -> None:
    r = flights[spec]
    if isinstance(r, Exception):
        raise r
    print(r.report())  # the numbers, kept for -rP / the log even when the case passes
    assert CASES[spec.case] is r.case
    problems = _problems(r)
    open_starts, why = REPORTED.get(spec.id, ((), ""))
    known = [p for p in problems if p.startswith(open_starts)]
    hard = [p for p in problems if p not in known]
    assert not hard, "; ".join(problems) + "\n" + r.report()
    if known:
        pytest.xfail(f"{'; '.join(known)}: {why}")
