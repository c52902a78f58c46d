"""3S LiPo battery: open-circuit voltage from state of charge, sag under current, run-down.

Terminal voltage V = n_cells·OCV(SoC) - I·R. The open-circuit curve is a typical LiPo discharge
curve per cell. Current comes from the motors' shaft power (see physics), so a loaded, emptying
battery gives a lower voltage, and with it a lower maximum rotor speed and thrust.
"""

from __future__ import annotations

import bisect

from sitl.params import VehicleParams
from sitl.tick_record import tick_record

# (state of charge 0..1, open-circuit volts per cell), ascending in charge.
_OCV_TABLE: tuple[tuple[float, float], ...] = (
    (0.00, 3.27),
    (0.05, 3.50),
    (0.10, 3.60),
    (0.20, 3.70),
    (0.30, 3.75),
    (0.40, 3.79),
    (0.50, 3.82),
    (0.60, 3.87),
    (0.70, 3.92),
    (0.80, 3.98),
    (0.90, 4.06),
    (1.00, 4.20),
)
_OCV_SOC = tuple(s for s, _ in _OCV_TABLE)
_OCV_V = tuple(v for _, v in _OCV_TABLE)


@tick_record
class BatteryState:
    """What a power module reports."""

    voltage_v: float
    current_a: float
    remaining_pct: float
    used_mah: float


def cell_ocv_v(soc: float) -> float:
    """Open-circuit volts of one cell at state of charge soc (0..1, clamped)."""
    if soc <= 0.0:
        return _OCV_V[0]
    if soc >= 1.0:
        return _OCV_V[-1]
    i = bisect.bisect_right(_OCV_SOC, soc)
    s0, s1 = _OCV_SOC[i - 1], _OCV_SOC[i]
    v0, v1 = _OCV_V[i - 1], _OCV_V[i]
    return v0 + (v1 - v0) * (soc - s0) / (s1 - s0)


def state_of_charge(p: VehicleParams, used_mah: float) -> float:
    """Remaining fraction 0..1."""
    return min(max(1.0 - used_mah / p.battery_capacity_mah, 0.0), 1.0)


def terminal_voltage_v(p: VehicleParams, used_mah: float, current_a: float) -> float:
    """Pack voltage under load (never below 0)."""
    ocv = p.battery_cells * cell_ocv_v(state_of_charge(p, used_mah))
    return max(ocv - current_a * p.battery_resistance_ohm, 0.0)


def battery_state(p: VehicleParams, used_mah: float, current_a: float) -> BatteryState:
    """Report for the given charge used and present current."""
    return BatteryState(
        voltage_v=terminal_voltage_v(p, used_mah, current_a),
        current_a=current_a,
        remaining_pct=100.0 * state_of_charge(p, used_mah),
        used_mah=used_mah,
    )
