"""When a station that stops, or dies, must land the vehicle first, and when it may leave."""

from __future__ import annotations

from gcs.supervisor import AIRBORNE_CAPABLE, SupervisorState

LAND_UNTIL = AIRBORNE_CAPABLE | {SupervisorState.KILLED, SupervisorState.LINK_LOST}
"""States in which a stopping station lands the vehicle before it lets go."""

LAND_WAIT_STATES = frozenset({SupervisorState.RELEASED, SupervisorState.DISARMED,
                              SupervisorState.SILENT})
"""A stopping station may leave once the supervisor is in one of these (a lost link first gets
its LAND requests, then the silence that lets the vehicle's failsafe act)."""

LAND_ON_DEATH = AIRBORNE_CAPABLE | {SupervisorState.LINK_LOST}
"""States in which a station that dies (its loop, or its whole process: `gcs.station.guardian`)
has the vehicle asked for LAND: it may be armed and in the air, and the station was flying it."""


def must_land(state: SupervisorState) -> bool:
    """A station stopping in `state` lands the vehicle (LAND confirmed) before letting go."""
    return state in LAND_UNTIL


def may_leave(state: SupervisorState) -> bool:
    """A stopping station has done its landing once the supervisor reaches `state`."""
    return state in LAND_WAIT_STATES


def lands_on_death(state: SupervisorState) -> bool:
    """A station whose loop dies in `state` asks for LAND on its way out."""
    return state in LAND_ON_DEATH
