"""The altitude the hold flies on: the estimate's readings, followed more closely.

The estimator trusts its accelerometer enough to coast through sonar gaps, learn its bias and
judge every reading against a narrow gate; in a steady hover that same trust makes the
estimate lag the sonar by tens of milliseconds where the altitude loop crosses over, and the
loop turns the lag into a slow wander of the vehicle (1.7 cm std against truth at 1 m on the
bundled SITL, while the estimate itself errs by 0.8 cm). Trusting the sonar more in the whole
filter halves the wander but costs the coasting, the bias and the carpet's gating.

So the hold gets its own two-state filter beside the estimator: it propagates on the
estimator's bias-corrected acceleration and takes exactly the readings the estimator accepted
(moved to the present for a late echo), with a process noise that puts its bandwidth well
above the loop's. Whenever the estimator has had no reading to offer for a while (coasting
through a gap longer than `control_coast_s`), re-based on another surface, or stands on the
floor, the control altitude is the estimator's: it never second-guesses the gate. Through a
shorter gap it coasts on the command the station sent, which knows better than a few aliased
accelerometer samples which way the vehicle is being pushed.
"""

from __future__ import annotations

import math

ControlState = list[float]  # [alt_m, vel_mps, P00, P01, P11]


def control_start(alt_m: float, vel_mps: float, alt_var_m2: float) -> ControlState:
    return [alt_m, vel_mps, alt_var_m2, 0.0, 0.1**2]


def control_predict(s: ControlState, acc_mps2: float, dt_s: float, accel_sigma: float) -> None:
    """Propagate over `dt_s` with the bias-corrected upward acceleration."""
    h, v, p00, p01, p11 = s
    half = 0.5 * dt_s * dt_s
    q = accel_sigma * accel_sigma
    s[0] = h + v * dt_s + acc_mps2 * half
    s[1] = v + acc_mps2 * dt_s
    # F = [[1, dt], [0, 1]]; process noise through G = (dt²/2, dt)
    n00 = p00 + 2.0 * dt_s * p01 + dt_s * dt_s * p11 + q * half * half
    n01 = p01 + dt_s * p11 + q * half * dt_s
    n11 = p11 + q * dt_s * dt_s
    s[2], s[3], s[4] = n00, n01, n11


def control_correct(s: ControlState, z_alt_m: float, r_m2: float) -> None:
    """Fuse an altitude reading the estimator accepted."""
    h, v, p00, p01, p11 = s
    inn = p00 + r_m2
    k0, k1 = p00 / inn, p01 / inn
    y = z_alt_m - h
    s[0] = h + k0 * y
    s[1] = v + k1 * y
    s[2] = (1.0 - k0) * p00
    s[3] = (1.0 - k0) * p01
    s[4] = p11 - k1 * p01


def control_follow(s: ControlState, alt_m: float, vel_mps: float, alt_sigma_m: float) -> None:
    """Take the estimator's altitude and velocity as they are."""
    var = alt_sigma_m * alt_sigma_m if math.isfinite(alt_sigma_m) else 0.01**2
    s[:] = control_start(alt_m, vel_mps, var)
