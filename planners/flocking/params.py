"""Tuning of the triangular flock (thesis Chapter 9): parameters and the policies they choose."""

from __future__ import annotations

import enum
from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from typing import Any

from planners.epbha.planner import EpbhaParams
from planners.flocking.formation import FormationParams
from planners.geometry import Vec3


class LeaderAvoider(enum.Enum):
    """How the root leader finds its way: EPBHA (Chapter 8, as Algorithm 9.3.3 says) or the
    flock's own simpler sidestep rule."""

    EPBHA = "epbha"
    SIDESTEP = "sidestep"


class FollowerPolicy(enum.Enum):
    """How a follower gets past an obstacle (§9.4: self avoidance or the leader's heads-up)."""

    SELF_AVOID = "self_avoid"
    HEADS_UP = "heads_up"


@dataclass(frozen=True, slots=True)
class FlockParams:
    """Tuning of the triangular flock; distances in metres, per planning step."""

    step_m: float = 0.1  # grid step d (§9.3.1)
    boost: float = 2.0  # catch-up speed factor of a follower given a new goal (§9.3.3 b)
    catchup_distance_m: float = 0.3  # a follower boosts when its goal is farther than this
    stop_distance_m: float = 0.3  # never step closer than this to what a sensor sees
    goal_tolerance_m: float = 0.05
    layer_spacing_m: float = 0.35  # altitude between layers in a narrow opening
    n_layers: int = 3
    trail_points: int = 800  # leader positions a follower remembers for heads-up
    obstacle_memory: int = 400  # sensor returns a vehicle remembers, as points in NED
    rejoin_clear_steps: int = 4  # steps with every sensor clear before leaving the trail
    rejoin_margin_m: float = 0.45  # the way back to the slot must pass this far from returns
    sidestep_overshoot_steps: int = 2
    cost_weights: Vec3 = (4.0, 2.0, 6.0)  # Definition 7's A, B (even), and one for altitude
    common_wait_steps: int = 150  # how long the root waits at the common goal for its team
    make_way_steps: int = 2  # a vehicle that stepped aside keeps clear this long
    overfly_after_steps: int = 4  # blocked this long by teammates, a vehicle flies over them
    overfly_height_m: float = 0.7  # above its goal altitude; more than the safe distance
    policy: FollowerPolicy = FollowerPolicy.HEADS_UP
    leader_avoider: LeaderAvoider = LeaderAvoider.EPBHA
    # The leader keeps the followers' 0.3 m stop distance, not EPBHA's 0.25 m: a corner 0.14 m
    # off its path sits between the cone's rays and is seen only as the side face behind it.
    epbha: EpbhaParams = field(default_factory=lambda: EpbhaParams(keep_off_m=0.3))
    latency_steps: int = 0
    formation: FormationParams = field(default_factory=FormationParams)

    def __post_init__(self) -> None:
        if not 0.0 < self.step_m < self.formation.safe_distance_m:
            raise ValueError(f"step_m must be in (0, safe distance), got {self.step_m}")
        if self.boost < 1.0:
            raise ValueError(f"boost must be >= 1, got {self.boost}")
        if self.n_layers < 1 or self.layer_spacing_m < 0.0:
            raise ValueError("n_layers must be >= 1 and layer_spacing_m >= 0")
        if self.overfly_height_m < self.formation.safe_distance_m:
            raise ValueError("overfly_height_m must be at least the safe distance")

    @classmethod
    def from_mapping(cls, data: Mapping[str, Any]) -> FlockParams:
        """Defaults overridden by a parsed TOML table; [formation] and [epbha] sub-tables nest.

        Unknown keys and bad enum names raise ValueError naming the key and what is allowed.
        """
        known = {f.name for f in fields(cls)}
        unknown = sorted(set(data) - known)
        if unknown:
            raise ValueError(
                f"flock params: unknown key(s) {unknown}; expected some of {sorted(known)}"
            )
        kw: dict[str, Any] = dict(data)
        if "formation" in kw:
            kw["formation"] = _sub_params(FormationParams, "formation", kw["formation"])
        if "epbha" in kw:
            kw["epbha"] = _sub_params(EpbhaParams, "epbha", kw["epbha"])
        for key, enum_type in (("policy", FollowerPolicy), ("leader_avoider", LeaderAvoider)):
            if key in kw:
                try:
                    kw[key] = enum_type(kw[key])
                except ValueError:
                    allowed = [e.value for e in enum_type]
                    raise ValueError(
                        f"flock params: {key} = {kw[key]!r}; expected one of {allowed}"
                    ) from None
        if "cost_weights" in kw:
            kw["cost_weights"] = tuple(float(w) for w in kw["cost_weights"])
        return cls(**kw)


def _sub_params(cls: type, name: str, data: Any) -> Any:
    """One nested parameter table from a mapping, unknown keys refused."""
    if not isinstance(data, Mapping):
        raise ValueError(f"flock params: [{name}] must be a table")
    known = {f.name for f in fields(cls)}
    unknown = sorted(set(data) - known)
    if unknown:
        raise ValueError(f"flock params: unknown key(s) {unknown} in [{name}]")
    return cls(**data)
