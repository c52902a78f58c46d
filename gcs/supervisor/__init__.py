"""The flight supervisor: one pure state machine that decides every tick what is safe."""

from gcs.supervisor.outcomes import ARM_FAILED, Outcome, OutcomeKind
from gcs.supervisor.params import SupervisorParams
from gcs.supervisor.supervisor import Supervisor
from gcs.supervisor.types import (
    AIRBORNE_CAPABLE,
    PC_CONTROL,
    Action,
    ActionKind,
    Intent,
    IntentKind,
    Level,
    LinkHealth,
    Note,
    SupervisorOutput,
    SupervisorState,
    TickIn,
    Transition,
    VehicleStatus,
)

__all__ = [
    "AIRBORNE_CAPABLE",
    "ARM_FAILED",
    "PC_CONTROL",
    "Action",
    "ActionKind",
    "Intent",
    "IntentKind",
    "Level",
    "LinkHealth",
    "Note",
    "Outcome",
    "OutcomeKind",
    "Supervisor",
    "SupervisorOutput",
    "SupervisorParams",
    "SupervisorState",
    "TickIn",
    "Transition",
    "VehicleStatus",
]
