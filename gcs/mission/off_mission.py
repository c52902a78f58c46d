"""When a mission's vehicle is no longer flying the mission: the autopilot or the link took it.

An autopilot failsafe (battery, GCS) switches to LAND by itself, a firmware disarms, a link goes
quiet: the mission must stop there and say why, or it goes on commanding a vehicle nobody flies
(and records readings taken on the floor as if they were flown).
"""

from __future__ import annotations

from firmware_link.records import Battery, FlightMode, StatusText
from gcs.station.station import StationSnapshot


def off_mission(snap: StationSnapshot, t_airborne_s: float) -> str | None:
    """Why a vehicle flying a mission in STABILIZE no longer is (None while it still is).

    An autopilot failsafe (battery, GCS) switches to LAND by itself: the mission must stop
    there, or it records readings taken on the floor as if they were flown.
    """
    if snap.link_lost:
        why = "link lost"
    elif not snap.armed:
        why = "disarmed"
    elif snap.vehicle_mode >= 0 and snap.vehicle_mode != FlightMode.STABILIZE:
        try:
            why = f"switched to {FlightMode(snap.vehicle_mode).name}"
        except ValueError:
            why = f"switched to mode {snap.vehicle_mode}"
    else:
        return None
    details = [f"after {t_airborne_s:.0f} s of flight"]
    batt = snap.latest.get(Battery)
    if isinstance(batt, Battery):
        details.append(f"battery {batt.voltage_v:.2f} V"
                       + (f" {batt.remaining_pct} %" if batt.remaining_pct >= 0 else ""))
    text = snap.latest.get(StatusText)
    if isinstance(text, StatusText) and "failsafe" in text.text.lower():
        details.append(f"vehicle said '{text.text}'")
    return f"vehicle {why} ({', '.join(details)})"
