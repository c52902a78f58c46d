"""Campaigns: many seeded lockstep flights from one file, run as Ray tasks, kept as rows.

`load_campaign` checks a file (`[fly]` flights or a mission file); `run_campaign` (grid, random)
and `run_search` (Optuna TPE, flights only) fly it inside `ray_session`; results are Parquet
rows (`read_results`), summarised by `summary_table` (`mission_summary_table`) and drawn by
`axis_plots`.
"""

from lab.campaign.driver import Outcome, run_campaign
from lab.campaign.pool import ray_session
from lab.campaign.results import (
    RESULTS_NAME,
    mission_summary_table,
    read_results,
    summary_table,
)
from lab.campaign.search import BEST_NAME, SearchOutcome, run_search
from lab.campaign.spec import load_campaign
from lab.campaign.types import BaseMission, Campaign, CampaignError

__all__ = [
    "BEST_NAME",
    "RESULTS_NAME",
    "BaseMission",
    "Campaign",
    "CampaignError",
    "Outcome",
    "SearchOutcome",
    "load_campaign",
    "mission_summary_table",
    "ray_session",
    "read_results",
    "run_campaign",
    "run_search",
    "summary_table",
]
