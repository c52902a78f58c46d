"""The SITL's onboard ALT_HOLD and rangefinder against the real firmware's `althold-steps`
fixtures (ArduCopter 4.7-dev and 3.2.1; fixtures/README.md), per stick step.

For each profile: the fixture's steps (true height from its `-truth.csv`), the SITL flying the
same steps in lockstep with its sensors' imperfections off (as the fixtures' simulators had
none) and on (the DESIGN.md realism floor): climb rate and height spread over the last 2 s of
each 4 s step. Then a 45 s hold at ~1.5 m: the spread of the true height over 5 s windows (real
4.7: 0.10-0.14 cm, ECOSYSTEM.md), noise off and on. Then the rangefinder readings sent while
the vehicle climbed through the band below RNGFND min (0.2 m), real and SITL.

Prints numbers; asserts nothing (tests/sitl/test_althold_conformance.py asserts).

    .venv/bin/python bench/althold_conformance.py [--seed 1]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from sitl.autopilot import Profile
from tests.sitl.althold_steps import (
    FIRMWARE,
    SitlFlight,
    fixture_rangefinder,
    fixture_steps,
    fly_steps,
)

RNG_MIN_M = 0.2


def window_std_cm(flight: SitlFlight, last_s: float = 40.0, window_s: float = 5.0) -> list[float]:
    """Spread of the true height in consecutive windows over the flight's last `last_s`."""
    sel = flight.t_s >= flight.t_s[-1] - last_s
    a = flight.alt_m[sel]
    n = round(window_s * 100.0)
    return [float(np.std(a[i : i + n]) * 100.0) for i in range(0, len(a) - n + 1, n)]


def steps_table(profile: Profile, seed: int) -> None:
    real = fixture_steps(profile)
    t0 = time.perf_counter()
    clean = fly_steps(profile, seed=seed, noise=False)
    noisy = fly_steps(profile, seed=seed, noise=True)
    wall = time.perf_counter() - t0
    print(f"\n{profile.value} (ArduCopter {FIRMWARE[profile]}), stick steps of 4 s; climb rate "
          f"m/s and height std cm over each step's last 2 s ({wall:.1f} s wall for both flights)")
    print(f"{'us':>5} | {'real':>7} {'std':>5} | {'SITL':>7} {'std':>5} {'diff':>6} | "
          f"{'noisy':>7} {'std':>5} | {'travel real':>11} {'SITL':>6}")
    for r, c, n in zip(real, clean.steps, noisy.steps, strict=True):
        print(f"{r.us:>5} | {r.rate_ms:+7.3f} {r.std_cm:5.2f} | {c.rate_ms:+7.3f} {c.std_cm:5.2f} "
              f"{c.rate_ms - r.rate_ms:+6.3f} | {n.rate_ms:+7.3f} {n.std_cm:5.2f} | "
              f"{r.end_m - r.start_m:+11.2f} {c.end_m - c.start_m:+6.2f}")
    real_rng = [x.distance_m for x in fixture_rangefinder(profile)]
    band_real = sorted({round(d, 2) for d in real_rng if 0.0 < d < RNG_MIN_M})
    band_sitl = sorted({round(d, 2) for _, d, _ in clean.ranges if 0.0 < d < RNG_MIN_M})
    print(f"rangefinder below {RNG_MIN_M} m, values sent: real {band_real}, SITL {band_sitl}")


def hold_table(profile: Profile, seed: int) -> None:
    for noise in (False, True):
        flight = fly_steps(profile, seed=seed, noise=noise, settle_s=45.0, steps=())
        stds = window_std_cm(flight)
        sel = flight.t_s >= flight.t_s[-1] - 40.0
        print(f"{profile.value} hold, noise {'on ' if noise else 'off'}: mean "
              f"{flight.alt_m[sel].mean():.2f} m, std over 40 s "
              f"{np.std(flight.alt_m[sel]) * 100:.2f} cm, 5 s windows "
              f"{min(stds):.2f}-{max(stds):.2f} cm")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    for profile in (Profile.COPTER4, Profile.APM25):
        steps_table(profile, args.seed)
    print("\nonboard ALT_HOLD at ~1.5 m (real 4.7: 0.10-0.14 cm per 5 s window)")
    for profile in (Profile.COPTER4, Profile.APM25):
        hold_table(profile, args.seed)


if __name__ == "__main__":
    main()
