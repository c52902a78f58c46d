"""One tick of the failsafes of an `Autopilot`: the timers of `failsafe.py`, the decisions of
`failsafe_rules.py`, and their effect on the vehicle (mode, overrides, disarm, texts)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from sitl.autopilot.arming import Severity
from sitl.autopilot.failsafe_rules import (
    Decision,
    Response,
    Situation,
    gcs_apm25,
    gcs_copter4,
    radio_apm25,
    radio_copter4,
)
from sitl.autopilot.params import Key
from sitl.autopilot.profile import FlightMode, Profile, RcInput

if TYPE_CHECKING:
    from sitl.autopilot.autopilot import Autopilot


def situation(ap: Autopilot, throttle_zero: bool) -> Situation:
    """What the failsafe code sees of the vehicle now."""
    st = ap.state
    radius_m = ap.params.k(Key.WP_RADIUS_CM) / 100.0
    return Situation(
        armed=st.armed,
        mode=st.mode,
        landed=ap.land.landed,
        throttle_zero=throttle_zero,
        gps=ap.options.gps,
        home_far=ap.options.home_distance_m > radius_m,
    )


def apply(ap: Autopilot, decision: Decision) -> None:
    """Carry out a failsafe's decision."""
    if decision.text is not None:
        ap.texts.append((int(Severity.WARNING), decision.text))
    st = ap.state
    r = decision.response
    if r is Response.DISARM and st.armed:
        ap.force_disarm()
    elif r is Response.LAND and st.mode is not FlightMode.LAND:
        ap.land_with_pause()
    elif r is Response.RTL and st.mode is not FlightMode.RTL:
        ap.enter_mode(FlightMode.RTL)
    elif r is Response.SMART_RTL and st.mode is not FlightMode.SMART_RTL:
        ap.enter_mode(FlightMode.SMART_RTL)


def _radio(ap: Autopilot, t_s: float, throttle_zero: bool) -> None:
    st = ap.state
    apm = ap.profile is Profile.APM25
    enabled = int(ap.params.k(Key.FS_THR_ENABLE))
    if enabled == 0 or ap.options.rc_input is not RcInput.ABSENT:
        if st.radio_failsafe:
            st.radio_failsafe = ap.radio_watch.active = False
        return
    change = ap.radio_watch.check(t_s, st.armed, ap.params.k(Key.RADIO_TIMEOUT_S))
    if change is True:
        st.radio_failsafe = True
        s = situation(ap, throttle_zero)
        if apm:
            apply(ap, radio_apm25(enabled, s))
        else:
            apply(ap, radio_copter4(enabled, int(ap.params.k(Key.FS_OPTIONS)), s))
    elif change is False:
        st.radio_failsafe = False
        if not apm:
            ap.texts.append((int(Severity.WARNING), "Radio Failsafe Cleared"))


def _gcs(ap: Autopilot, t_s: float, throttle_zero: bool, timeout_s: float) -> None:
    st = ap.state
    apm = ap.profile is Profile.APM25
    enabled = int(ap.params.k(Key.FS_GCS_ENABLE))
    change = None
    # 3.2.1 checks only while armed; 4.x armed or not (disarmed it only says so)
    if (enabled and (st.armed or not apm)) or ap.gcs.active:
        change = ap.gcs.check(
            t_s, requires_override=apm, override_active=ap.radio.overridden, timeout_s=timeout_s
        )
    if change is True:
        st.gcs_failsafe = True
        ap.radio.clear_overrides()  # both firmwares, before anything else
        s = situation(ap, throttle_zero)
        if apm:
            apply(ap, gcs_apm25(s))
        else:
            apply(ap, gcs_copter4(enabled, int(ap.params.k(Key.FS_OPTIONS)), s))
    elif change is False:
        st.gcs_failsafe = False
        if not apm:
            ap.texts.append((int(Severity.INFO), "GCS Failsafe Cleared"))


def run_failsafes(ap: Autopilot, t_s: float, battery_v: float, gcs_timeout_s: float) -> None:
    """Radio, GCS and battery failsafes for one tick."""
    # the throttle as the failsafe code sees it, before the overrides are cleared
    throttle_zero = ap.throttle_stick() <= 0.0
    _radio(ap, t_s, throttle_zero)
    _gcs(ap, t_s, throttle_zero, gcs_timeout_s)
    st = ap.state
    enabled = ap.params.k(Key.FS_BATT_ENABLE) > 0
    threshold = ap.params.k(Key.FS_BATT_VOLTAGE)
    if enabled and ap.battery.check(t_s, battery_v, threshold):
        st.battery_failsafe = True
        ap.texts.append((int(Severity.CRITICAL), f"Battery failsafe: {battery_v:.2f}V"))
        if st.armed:
            if ap.land.landed:
                ap.force_disarm()
            elif st.mode is not FlightMode.LAND:
                ap.land_with_pause()
