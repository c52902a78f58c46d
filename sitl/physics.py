"""6-DOF rigid-body quadrotor in the thesis's "+" configuration, with motors, battery and contact.

Motor order is (front, right, back, left). Front and back spin clockwise seen from above, right
and left counter-clockwise (thesis Ch. 3). Body frame FRD, world frame local NED, q_nb = (w,x,y,z).

Forces and torques, and where they depart from the thesis's equations:
- Thrust (eq. 3.3): T = T_f + T_r + T_b + T_l along body -z; T_i = k_t·ω_i².
- Roll torque: eq. 3.4 repeats eq. 3.3. With arm length l, rotor thrust at r_i along -z gives
  τ = r_i × F_i, so τ_x = l·(T_l − T_r): more thrust on the right rolls left (negative roll).
- Pitch torque (eq. 3.5): τ_y = l·(T_f − T_b): more front thrust pitches nose up (positive).
- Yaw torque: eq. 3.6 writes a sum of thrusts. It is the sum of the rotors' reaction torques
  Q_i = k_m·ω_i². A rotor spinning clockwise seen from above has angular velocity along body +z
  (down); the air's drag torque on it is countered by the motor, whose reaction on the frame is
  along −z. So τ_z = k_m·(ω_r² + ω_l² − ω_f² − ω_b²): speeding up the clockwise pair yaws the
  nose left (negative yaw rate).
- Rotational dynamics: eq. 3.8 divides the torques by the mass. Euler's equation is
  ω̇ = J⁻¹(τ − ω × Jω), J diagonal (see sitl.params for the inertia).
- Translation: eq. 3.7 is written in the body frame; here Newton's law is integrated in NED,
  m·a = R(q)·(0, 0, −T) + m·g·e_z − (c₁ + c₂·|v|)·v, which is the same physics.

Integration is semi-implicit Euler at dt ≤ 2.5 ms: velocity first, then position with the new
velocity; quaternion by q ← q ⊗ (1, ω·dt/2), renormalised every step.

Contact: the floor (or a box top) supports the skids. A vehicle resting with thrust below weight
keeps z, has zero vertical velocity and level attitude, and Coulomb friction stops sliding; a
touchdown is perfectly inelastic (no bounce, no energy gained). Hitting a wall, the ceiling or a
box with the body (a vertical cylinder of the arm-tip radius) stops the vehicle where it was
and names the obstacle in `collided_with`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from sitl.battery import cell_ocv_v
from sitl.geometry import Geometry, geometry
from sitl.motors import clamp_throttle
from sitl.params import GRAVITY_MPS2, VehicleParams, derived
from sitl.rotation import quat_from_euler
from sitl.world import World

G = GRAVITY_MPS2
# A contact counts as a collision when it begins at this speed or more; pressing on an obstacle
# re-touches it at millimetres per second and is not counted again.
IMPACT_SPEED_MPS = 0.1
IMPACT2 = IMPACT_SPEED_MPS**2


class Core:
    """Mutable plain-float state the integrator updates in place (the hot path)."""

    __slots__ = (
        "ax",
        "ay",
        "az",
        "collided_with",
        "collisions",
        "current_a",
        "m0",
        "m1",
        "m2",
        "m3",
        "on_ground",
        "p",
        "q",
        "qw",
        "qx",
        "qy",
        "qz",
        "r",
        "used_mah",
        "voltage_v",
        "vx",
        "vy",
        "vz",
        "x",
        "y",
        "z",
    )

    def __init__(self) -> None:
        self.x = self.y = self.z = 0.0
        self.vx = self.vy = self.vz = 0.0
        self.ax = self.ay = self.az = 0.0
        self.qw, self.qx, self.qy, self.qz = 1.0, 0.0, 0.0, 0.0
        self.p = self.q = self.r = 0.0
        self.m0 = self.m1 = self.m2 = self.m3 = 0.0
        self.used_mah = 0.0
        self.current_a = 0.0
        self.voltage_v = 0.0
        self.on_ground = False
        self.collided_with: str | None = None
        self.collisions = 0  # contacts begun at >= IMPACT_SPEED_MPS


class SubStep:
    """What every sub-step of length `dt` for airframe `prm` shares, worked out once.

    The integrator runs 400 times a simulated second; re-deriving these (the motor lag's
    exponential, the derived constants, a dozen parameter lookups) on every call was a fifth of
    its cost. Each value is the very expression `advance` used to evaluate, so results are the
    same to the last bit.
    """

    __slots__ = (
        "alpha",
        "arm",
        "avionics_a",
        "capacity_mah",
        "cells",
        "crot",
        "drag_lin",
        "drag_quad",
        "dt",
        "e",
        "friction",
        "gear_m",
        "half_dt",
        "half_height_m",
        "inv_mass",
        "ixx",
        "iyy",
        "izz",
        "k_thrust",
        "k_torque",
        "lin",
        "motor_eff",
        "omega_max_ref",
        "prm",
        "radius_m",
        "ref_voltage",
        "resistance",
        "x_iyy_izz",
        "y_izz_ixx",
        "z_ixx_iyy",
    )

    def __init__(self, prm: VehicleParams, dt: float) -> None:
        d = derived(prm)
        self.prm = prm
        self.dt = dt
        self.half_dt = 0.5 * dt
        self.alpha = 1.0 - math.exp(-dt / prm.motor_lag_s)
        self.e = prm.thrust_expo
        self.lin = 1.0 - prm.thrust_expo
        self.omega_max_ref = d.omega_max_ref_radps
        self.ref_voltage = prm.ref_voltage_v
        self.k_thrust = d.k_thrust
        self.k_torque = d.k_torque
        self.avionics_a = prm.avionics_current_a
        self.motor_eff = prm.motor_efficiency
        self.capacity_mah = prm.battery_capacity_mah
        self.cells = prm.battery_cells
        self.resistance = prm.battery_resistance_ohm
        self.drag_lin = prm.drag_lin_n_per_mps
        self.drag_quad = prm.drag_quad_n_per_mps2
        self.inv_mass = d.inv_mass
        self.friction = prm.ground_friction
        self.radius_m = prm.body_radius_m
        self.half_height_m = prm.body_half_height_m
        self.gear_m = prm.gear_height_m
        self.arm = d.arm_m
        self.crot = prm.rot_drag_nm_per_radps
        self.ixx, self.iyy, self.izz = d.ixx, d.iyy, d.izz
        self.x_iyy_izz = d.izz - d.iyy  # the gyroscopic terms' inertia differences
        self.y_izz_ixx = d.ixx - d.izz
        self.z_ixx_iyy = d.iyy - d.ixx

    def speed_fraction(self, u: float) -> float:
        """Steady rotor speed at throttle u as a fraction of the maximum (thrust ∝ its square)."""
        return math.sqrt(self.lin * u + self.e * u * u)


_substep_of: dict[tuple[int, float], SubStep] = {}


def sub_step(prm: VehicleParams, dt: float) -> SubStep:
    """The SubStep of (prm, dt), cached by the identity of prm (held, so its id stays)."""
    k = _substep_of.get((id(prm), dt))
    if k is not None and k.prm is prm:
        return k
    if len(_substep_of) >= 64:
        _substep_of.clear()
    k = _substep_of[(id(prm), dt)] = SubStep(prm, dt)
    return k


def advance(
    c: Core,
    u0: float,
    u1: float,
    u2: float,
    u3: float,
    prm: VehicleParams,
    geom: Geometry,
    dt: float,
) -> None:
    """Advance `c` by one sub-step dt (≤ prm.max_dt_s) with throttles u (0..1, pre-clamped)."""
    k = sub_step(prm, dt)
    speed = k.speed_fraction
    advance_at(c, speed(u0), speed(u1), speed(u2), speed(u3), k, geom)


def advance_at(
    c: Core, f0: float, f1: float, f2: float, f3: float, k: SubStep, geom: Geometry
) -> None:
    """`advance` with the motors' steady speed fractions (`SubStep.speed_fraction` of the
    throttles) given: a caller that holds the throttles over several sub-steps works them out
    once."""
    dt = k.dt
    # Motors: steady speed from throttle and battery volts, first-order lag (exact discrete).
    wmax = k.omega_max_ref * c.voltage_v / k.ref_voltage
    alpha = k.alpha
    m0 = c.m0 + (wmax * f0 - c.m0) * alpha
    m1 = c.m1 + (wmax * f1 - c.m1) * alpha
    m2 = c.m2 + (wmax * f2 - c.m2) * alpha
    m3 = c.m3 + (wmax * f3 - c.m3) * alpha
    c.m0, c.m1, c.m2, c.m3 = m0, m1, m2, m3
    s0, s1, s2, s3 = m0 * m0, m1 * m1, m2 * m2, m3 * m3
    kt = k.k_thrust
    thrust = kt * (s0 + s1 + s2 + s3)

    # Battery: shaft power k_m·ω³ over efficiency, at the previous terminal voltage.
    shaft_w = k.k_torque * (s0 * m0 + s1 * m1 + s2 * m2 + s3 * m3)
    v_prev = c.voltage_v
    current = k.avionics_a + (shaft_w / (k.motor_eff * v_prev) if v_prev > 0.5 else 0.0)
    used = c.used_mah + current * dt / 3.6
    soc = 1.0 - used / k.capacity_mah
    ocv = k.cells * cell_ocv_v(soc)
    c.used_mah = used
    c.current_a = current
    v = ocv - current * k.resistance
    c.voltage_v = 0.0 if v < 0.0 else v  # max(v, 0.0) without the call, -0.0 and NaN alike

    # Forces in NED.
    qw, qx, qy, qz = c.qw, c.qx, c.qy, c.qz
    bzx = 2.0 * (qx * qz + qw * qy)  # body +z axis expressed in NED
    bzy = 2.0 * (qy * qz - qw * qx)
    bzz = 1.0 - 2.0 * (qx * qx + qy * qy)
    vx, vy, vz = c.vx, c.vy, c.vz
    drag = k.drag_lin + k.drag_quad * math.sqrt(
        vx * vx + vy * vy + vz * vz
    )
    im = k.inv_mass
    ax = (-thrust * bzx - drag * vx) * im
    ay = (-thrust * bzy - drag * vy) * im
    az = (-thrust * bzz - drag * vz) * im + G

    if c.on_ground and az >= 0.0:
        # Resting on the support: the normal force cancels az; friction brakes any slide.
        speed_h = math.sqrt(vx * vx + vy * vy)
        nvx = nvy = 0.0
        if speed_h > 0.0:
            decel = k.friction * az * dt
            keep = max(speed_h - decel, 0.0) / speed_h
            nvx, nvy = vx * keep, vy * keep
        c.x += nvx * dt
        c.y += nvy * dt
        c.ax, c.ay, c.az = (nvx - vx) / dt, (nvy - vy) / dt, -vz / dt
        c.vx, c.vy, c.vz = nvx, nvy, 0.0
        c.p = c.q = c.r = 0.0
        c.collided_with = None
        if nvx != 0.0 or nvy != 0.0:
            hit = geom.cylinder_hit(c.x, c.y, c.z, k.radius_m, k.half_height_m)
            if hit is not None:
                c.x -= nvx * dt
                c.y -= nvy * dt
                c.vx = c.vy = 0.0
                c.collided_with = hit
                if speed_h >= IMPACT_SPEED_MPS:
                    c.collisions += 1
            # Slid off the edge of a box top: fall from the next step on.
            c.on_ground = c.z >= geom.support_z(c.x, c.y, c.z) - k.gear_m - 1e-9
        return

    # Torques in FRD (see module docstring for the signs).
    arm = k.arm
    crot = k.crot
    p, q, r = c.p, c.q, c.r
    tx = arm * kt * (s3 - s1) - crot * p
    ty = arm * kt * (s0 - s2) - crot * q
    tz = k.k_torque * (s1 + s3 - s0 - s2) - crot * r
    p += (tx - q * r * k.x_iyy_izz) / k.ixx * dt
    q += (ty - r * p * k.y_izz_ixx) / k.iyy * dt
    r += (tz - p * q * k.z_ixx_iyy) / k.izz * dt
    c.p, c.q, c.r = p, q, r
    h = k.half_dt
    nw = qw - h * (qx * p + qy * q + qz * r)
    nx = qx + h * (qw * p + qy * r - qz * q)
    ny = qy + h * (qw * q + qz * p - qx * r)
    nz = qz + h * (qw * r + qx * q - qy * p)
    inv = 1.0 / math.sqrt(nw * nw + nx * nx + ny * ny + nz * nz)
    c.qw, c.qx, c.qy, c.qz = nw * inv, nx * inv, ny * inv, nz * inv

    nvx, nvy, nvz = vx + ax * dt, vy + ay * dt, vz + az * dt
    ox, oy, oz = c.x, c.y, c.z
    nx_, ny_, nz_ = ox + nvx * dt, oy + nvy * dt, oz + nvz * dt
    rest_z = geom.support_z(nx_, ny_, oz) - k.gear_m
    on_ground = nz_ >= rest_z
    if on_ground:
        # Inelastic touchdown: stop on the surface, attitude settles level on the skids.
        nz_ = rest_z
        if nvz > 0.0:
            nvz = 0.0
        c.p = c.q = c.r = 0.0
        yaw = math.atan2(2.0 * (c.qw * c.qz + c.qx * c.qy), 1.0 - 2.0 * (c.qy**2 + c.qz**2))
        c.qw, c.qx, c.qy, c.qz = math.cos(yaw / 2.0), 0.0, 0.0, math.sin(yaw / 2.0)
    hit = geom.cylinder_hit(nx_, ny_, nz_, k.radius_m, k.half_height_m)
    if hit is not None and (
        geom.cylinder_hit(ox, oy, oz, k.radius_m, k.half_height_m) is None
    ):
        # Stop at the last clear position (no tunnelling) and drop the velocity into the
        # obstacle; motion along its surface goes on, so a vehicle never hangs on a wall.
        nx_, ny_, nz_ = ox, oy, oz
        cx, cy, cz = geom.contact_normal(hit, (ox, oy, oz), (nx_, ny_, nz_), k.half_height_m)
        into = nvx * cx + nvy * cy + nvz * cz
        if into < 0.0:
            nvx -= into * cx
            nvy -= into * cy
            nvz -= into * cz
            sx, sy, sz = ox + nvx * dt, oy + nvy * dt, oz + nvz * dt
            if geom.cylinder_hit(sx, sy, sz, k.radius_m, k.half_height_m) is None:
                nx_, ny_, nz_ = sx, sy, sz
        on_ground = c.on_ground
    if hit is not None and c.collided_with is None and vx * vx + vy * vy + vz * vz >= IMPACT2:
        c.collisions += 1
    c.collided_with = hit
    c.ax, c.ay, c.az = (nvx - vx) / dt, (nvy - vy) / dt, (nvz - vz) / dt
    c.vx, c.vy, c.vz = nvx, nvy, nvz
    c.x, c.y, c.z = nx_, ny_, nz_
    c.on_ground = on_ground


def run(
    c: Core, motor_cmd: Sequence[float], prm: VehicleParams, geom: Geometry, dt_s: float
) -> None:
    """Advance `c` by dt_s in equal sub-steps no longer than prm.max_dt_s."""
    if not (dt_s > 0.0 and math.isfinite(dt_s)):
        raise ValueError(f"dt_s: expected a finite number > 0, got {dt_s!r}")
    u = [clamp_throttle(v) for v in motor_cmd]
    if len(u) != 4:
        raise ValueError(
            f"motor_cmd: expected 4 throttles (front, right, back, left), got {len(u)}"
        )
    n = max(1, math.ceil(dt_s / prm.max_dt_s - 1e-9))
    h = dt_s / n
    for _ in range(n):
        advance(c, u[0], u[1], u[2], u[3], prm, geom, h)


def initial_core(
    prm: VehicleParams, world: World, pos_n: Sequence[float], yaw_rad: float = 0.0
) -> Core:
    """A Core at pos_n; if pos_n is at or below the resting height it rests on the support."""
    geom = geometry(world)
    c = Core()
    c.x, c.y, c.z = (float(v) for v in pos_n)
    rest_z = geom.support_z(c.x, c.y, c.z) - prm.gear_height_m
    if c.z >= rest_z:
        c.z = rest_z
        c.on_ground = True
    c.qw, c.qx, c.qy, c.qz = quat_from_euler(0.0, 0.0, yaw_rad)
    c.current_a = prm.avionics_current_a
    c.voltage_v = prm.battery_cells * cell_ocv_v(1.0) - c.current_a * prm.battery_resistance_ohm
    return c
