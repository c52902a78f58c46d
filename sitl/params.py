"""Vehicle parameters of the simulated quadrotor (thesis Ch. 3, 4, 7), TOML-overridable.

Airframe: DJI F450 "+" configuration, 1.63 kg, 0.45 m motor-to-motor diagonal (Ch. 7), DJI 2212
920 KV motors with 10x4.5 props on a 3S LiPo (Ch. 4).

Inertia departs from eq. 3.9. The thesis models a central sphere (mass M0, radius r) with four
point-mass motors (mass m) on arms of length l and writes jx = jy = jz = 2·M0·r²/5 + 2·l²·m.
For a "+" frame the point masses give 2·l²·m about x and y (two motors off each axis) but
4·l²·m about z (all four are off the z axis), so the tensor is diagonal with a larger Izz:
    Ixx = Iyy = 2·M0·r²/5 + 2·l²·m,   Izz = 2·M0·r²/5 + 4·l²·m.
Chosen split (sums to 1.63 kg): each "motor" point mass is 0.16 kg (motor 56 g, propeller 13 g,
ESC 25 g and the outer arm with its landing-skid leg 66 g); the central sphere is the remaining
0.99 kg (plates, battery, autopilot, sensors) with radius 0.12 m. That gives Ixx = Iyy ≈
0.022 kg·m² and Izz ≈ 0.038 kg·m², in line with measured 450-size frames.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import types
import typing
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, TypeVar

GRAVITY_MPS2 = 9.80665

if TYPE_CHECKING:
    from _typeshed import DataclassInstance

_D = TypeVar("_D", bound="DataclassInstance")


class ParamError(ValueError):
    """A parameter value or TOML table is invalid; the message names the field."""


def check_positive(obj: object, *names: str) -> None:
    for name in names:
        value = getattr(obj, name)
        if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
            raise ParamError(f"{name}: expected a number > 0, got {value!r}")


def check_range(obj: object, name: str, lo: float, hi: float) -> None:
    value = getattr(obj, name)
    if not (isinstance(value, int | float) and lo <= value <= hi):
        raise ParamError(f"{name}: expected a number in [{lo}, {hi}], got {value!r}")


def _coerce(value: Any, hint: Any, where: str) -> Any:
    """Convert one TOML value to a dataclass field's type, or raise ParamError naming `where`."""
    origin = typing.get_origin(hint)
    if hint is float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise ParamError(f"{where}: expected a number, got {value!r}")
        if not math.isfinite(value):
            raise ParamError(f"{where}: expected a finite number, got {value!r}")
        return float(value)
    if hint is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise ParamError(f"{where}: expected an integer, got {value!r}")
        return value
    if hint is bool:
        if not isinstance(value, bool):
            raise ParamError(f"{where}: expected true or false, got {value!r}")
        return value
    if hint is str:
        if not isinstance(value, str):
            raise ParamError(f"{where}: expected a string, got {value!r}")
        return value
    if origin is tuple:
        args = typing.get_args(hint)
        if not isinstance(value, list | tuple):
            raise ParamError(f"{where}: expected a list of {len(args)} numbers, got {value!r}")
        if len(value) != len(args):
            raise ParamError(f"{where}: expected {len(args)} numbers, got {len(value)}")
        pairs = enumerate(zip(value, args, strict=True))
        return tuple(_coerce(v, a, f"{where}[{i}]") for i, (v, a) in pairs)
    if origin in (typing.Union, types.UnionType):
        members = [a for a in typing.get_args(hint) if a is not type(None)]
        if value is None:
            return None
        return _coerce(value, members[0], where)
    if isinstance(hint, type) and dataclasses.is_dataclass(hint):
        if not isinstance(value, Mapping):
            raise ParamError(f"{where}: expected a table, got {value!r}")
        return build_dataclass(hint, value, where)
    return value


def build_dataclass(cls: type[_D], data: Mapping[str, Any], where: str = "") -> _D:
    """Build frozen dataclass `cls` from a TOML table: unknown keys and bad types are errors.

    Missing keys keep their defaults. Errors read `<where>.<field>: <problem>`.
    """
    if not isinstance(data, Mapping):
        raise ParamError(f"{where or cls.__name__}: expected a table, got {data!r}")
    hints = typing.get_type_hints(cls)
    fields = {f.name for f in dataclasses.fields(cls) if f.init}
    kwargs: dict[str, Any] = {}
    prefix = f"{where}." if where else ""
    for key, value in data.items():
        if key not in fields:
            known = ", ".join(sorted(fields))
            raise ParamError(f"{prefix}{key}: unknown field (known: {known})")
        kwargs[key] = _coerce(value, hints[key], f"{prefix}{key}")
    try:
        return cls(**kwargs)
    except ParamError as exc:
        raise ParamError(f"{prefix}{exc}") from None


@dataclass(frozen=True, slots=True)
class VehicleParams:
    """Airframe, motors, drag and battery of the simulated quadrotor."""

    mass_kg: float = 1.63  # thesis Ch. 7
    diagonal_m: float = 0.45  # motor-to-motor, thesis Ch. 7
    motor_mass_kg: float = 0.16  # point mass per arm tip (see module docstring)
    sphere_radius_m: float = 0.12  # central sphere of eq. 3.9
    # Motors: DJI 2212 920 KV, 10x4.5 props. Thrust = k·ω² with ω ≤ ω_max(V) ∝ battery volts.
    max_thrust_per_motor_n: float = 8.0  # at ref_voltage_v: ≈ 2:1 thrust-to-weight
    ref_voltage_v: float = 11.1  # 3S nominal
    motor_kv_rpm_per_v: float = 920.0
    loaded_speed_fraction: float = 0.8  # prop-loaded speed / no-load KV·V
    # Thrust fraction at throttle u: (1 - e)·u + e·u²; ESC+prop curve (like MOT_THST_EXPO).
    thrust_expo: float = 0.3
    motor_lag_s: float = 0.05  # first-order time constant of rotor speed
    yaw_torque_per_thrust_m: float = 0.016  # rotor reaction torque / thrust (k_m / k_t)
    motor_efficiency: float = 0.7  # shaft power / electrical power
    # Drag on the whole body in NED: F = -(lin·v + quad·|v|·v).
    drag_lin_n_per_mps: float = 0.1  # rotor (induced) drag
    drag_quad_n_per_mps2: float = 0.03  # 0.5·ρ·Cd·A with A ≈ 0.05 m²
    rot_drag_nm_per_radps: float = 0.002  # aerodynamic damping of body rates
    # Contact and body geometry.
    gear_height_m: float = 0.06  # centre of gravity above the skid bottoms
    body_radius_m: float = 0.25  # arm tip + prop radius, for collisions
    body_half_height_m: float = 0.04  # vertical half-extent of the body, for collisions
    ground_friction: float = 0.6  # Coulomb coefficient skids/floor
    # Battery: 3S LiPo.
    battery_cells: int = 3
    battery_capacity_mah: float = 3000.0
    battery_resistance_ohm: float = 0.045  # pack internal resistance
    avionics_current_a: float = 0.5
    # Physics sub-step bound: integrate at >= 400 Hz.
    max_dt_s: float = 0.0025

    def __post_init__(self) -> None:
        check_positive(
            self,
            "mass_kg",
            "diagonal_m",
            "motor_mass_kg",
            "sphere_radius_m",
            "max_thrust_per_motor_n",
            "ref_voltage_v",
            "motor_kv_rpm_per_v",
            "motor_lag_s",
            "motor_efficiency",
            "gear_height_m",
            "body_radius_m",
            "body_half_height_m",
            "battery_capacity_mah",
            "battery_resistance_ohm",
            "max_dt_s",
        )
        check_range(self, "thrust_expo", 0.0, 1.0)
        check_range(self, "loaded_speed_fraction", 0.1, 1.0)
        check_range(self, "motor_efficiency", 0.05, 1.0)
        check_range(self, "yaw_torque_per_thrust_m", 0.0, 1.0)
        check_range(self, "drag_lin_n_per_mps", 0.0, 100.0)
        check_range(self, "drag_quad_n_per_mps2", 0.0, 100.0)
        check_range(self, "rot_drag_nm_per_radps", 0.0, 10.0)
        check_range(self, "ground_friction", 0.0, 5.0)
        check_range(self, "avionics_current_a", 0.0, 100.0)
        check_range(self, "max_dt_s", 1e-5, 0.0025)
        if self.battery_cells not in range(1, 13):
            raise ParamError(f"battery_cells: expected 1..12, got {self.battery_cells!r}")
        if 4 * self.motor_mass_kg >= self.mass_kg:
            raise ParamError(
                f"motor_mass_kg: four motors ({4 * self.motor_mass_kg:.3f} kg) must weigh less "
                f"than mass_kg ({self.mass_kg} kg)"
            )
        if self.body_half_height_m >= self.gear_height_m:
            raise ParamError("body_half_height_m: must be below gear_height_m (skids touch first)")

    @classmethod
    def from_toml(cls, data: Mapping[str, Any]) -> VehicleParams:
        """Parameters from a TOML table (e.g. a world's `[vehicle]`); unknown keys are errors."""
        return build_dataclass(cls, data)

    @property
    def arm_length_m(self) -> float:
        """Centre to motor: half the diagonal."""
        return self.diagonal_m / 2.0

    @property
    def central_mass_kg(self) -> float:
        """M0 of eq. 3.9: everything that is not a motor point mass."""
        return self.mass_kg - 4.0 * self.motor_mass_kg

    @property
    def inertia_kgm2(self) -> tuple[float, float, float]:
        """Diagonal inertia (Ixx, Iyy, Izz); see the module docstring for the departure from 3.9."""
        sphere = 0.4 * self.central_mass_kg * self.sphere_radius_m**2
        arm2 = self.arm_length_m**2 * self.motor_mass_kg
        return (sphere + 2.0 * arm2, sphere + 2.0 * arm2, sphere + 4.0 * arm2)

    @property
    def weight_n(self) -> float:
        """m·g."""
        return self.mass_kg * GRAVITY_MPS2


@dataclass(frozen=True, slots=True)
class Derived:
    """Constants derived once from VehicleParams for the integrator's hot path."""

    arm_m: float
    inv_mass: float
    ixx: float
    iyy: float
    izz: float
    k_thrust: float  # N / (rad/s)²
    k_torque: float  # N·m / (rad/s)²
    omega_max_ref_radps: float  # loaded rotor speed at ref voltage, full throttle


_derived_of: dict[int, tuple[VehicleParams, Derived]] = {}


def derived(p: VehicleParams) -> Derived:
    """Hot-path constants for `p`, found by identity: the integrator asks 400 times a simulated
    second, and hashing every field of a frozen dataclass each time was a tenth of its cost."""
    hit = _derived_of.get(id(p))
    if hit is not None and hit[0] is p:
        return hit[1]
    if len(_derived_of) >= 64:
        _derived_of.clear()
    d = _derive(p)
    _derived_of[id(p)] = (p, d)  # holding p keeps its id from being reused
    return d


@functools.lru_cache(maxsize=64)
def _derive(p: VehicleParams) -> Derived:
    """Hot-path constants for `p` (cached: params are frozen and hashable)."""
    ixx, iyy, izz = p.inertia_kgm2
    omega_max = p.motor_kv_rpm_per_v * p.ref_voltage_v * p.loaded_speed_fraction * math.pi / 30.0
    k_thrust = p.max_thrust_per_motor_n / omega_max**2
    return Derived(
        arm_m=p.arm_length_m,
        inv_mass=1.0 / p.mass_kg,
        ixx=ixx,
        iyy=iyy,
        izz=izz,
        k_thrust=k_thrust,
        k_torque=k_thrust * p.yaw_torque_per_thrust_m,
        omega_max_ref_radps=omega_max,
    )
