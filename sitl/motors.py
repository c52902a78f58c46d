"""Brushless motor + ESC + propeller: throttle to rotor speed (first-order lag), thrust, torque.

Thrust and the rotor's reaction (drag) torque both go with rotor speed squared:
T = k_t·ω², Q = k_m·ω². The ESC/prop curve maps throttle u (0..1) to the steady thrust fraction
(1 - e)·u + e·u² (the shape ArduPilot's MOT_THST_EXPO linearises), so the steady rotor speed is
ω_ss = ω_max(V)·sqrt((1 - e)·u + e·u²), with ω_max proportional to the battery's terminal voltage.
"""

from __future__ import annotations

import math

from sitl.params import VehicleParams, derived


def clamp_throttle(u: float) -> float:
    """Throttle limited to 0..1; NaN counts as 0 (motor stopped), never as full power."""
    if not u > 0.0:
        return 0.0
    return 1.0 if u > 1.0 else u


def throttle_for_fraction(fraction: float, expo: float) -> float:
    """The throttle whose steady thrust fraction (1 - e)·u + e·u² is `fraction` (0..1)."""
    if fraction <= 0.0:
        return 0.0
    if expo <= 1e-9:
        return min(fraction, 1.0)
    a, b = expo, 1.0 - expo
    u = (-b + math.sqrt(b * b + 4.0 * a * fraction)) / (2.0 * a)
    return min(max(u, 0.0), 1.0)


def max_speed_radps(p: VehicleParams, voltage_v: float) -> float:
    """Full-throttle loaded rotor speed at battery terminal voltage `voltage_v`."""
    return derived(p).omega_max_ref_radps * max(voltage_v, 0.0) / p.ref_voltage_v


def thrust_n(p: VehicleParams, omega_radps: float) -> float:
    """Rotor thrust T = k_t·ω²."""
    return derived(p).k_thrust * omega_radps * omega_radps
