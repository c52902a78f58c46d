"""Physics of the simulated quadrotor: equilibrium, free fall, torque signs, contact, battery."""

from __future__ import annotations

import numpy as np
import pytest

from sitl.params import GRAVITY_MPS2
from sitl.vehicle_model import SimVehicle
from sitl.world import default_world

DT = 0.0025


def make(z_m: float = 0.0, *, hovering: bool = False, **kw: object) -> SimVehicle:
    """A noise-free vehicle at the centre of the default room."""
    return SimVehicle(
        default_world(),
        start_pos_n=(0.0, 0.0, z_m),
        rng=np.random.default_rng(7),
        noise=False,
        start_hovering=hovering,
        **kw,  # type: ignore[arg-type]
    )


def run(v: SimVehicle, cmd: list[float], seconds: float, dt: float = DT) -> None:
    for _ in range(round(seconds / dt)):
        v.step(cmd, dt)


def test_analytic_hover_throttle_holds_altitude_open_loop() -> None:
    v = make(-1.0, hovering=True)
    u = v.hover_throttle()
    assert 0.4 < u < 0.6  # ≈ 2:1 thrust-to-weight hovers near half throttle
    run(v, [u] * 4, 2.0)
    t = v.truth
    assert abs(t.pos_n[2] - -1.0) < 0.03
    assert abs(t.vel_n[2]) < 0.05
    assert not t.on_ground


def test_free_fall_matches_g_before_drag_matters() -> None:
    v = make(-2.0)
    assert not v.truth.on_ground
    run(v, [0.0] * 4, 0.3)
    t = v.truth
    fallen = t.pos_n[2] - -2.0
    assert fallen == pytest.approx(0.5 * GRAVITY_MPS2 * 0.3**2, rel=0.02)
    assert t.vel_n[2] == pytest.approx(GRAVITY_MPS2 * 0.3, rel=0.03)
