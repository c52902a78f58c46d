"""Fast radiation intensity contour maps with one UAV (thesis Chapter 10): the public names.

The concepts live in their own modules: parameters and phases (``params``), what the mapper
hands out (``types``), its evidence model (``evidence``: a Gaussian process, ``gp``, and
contours, ``contour``), the mapper (``mapper``, whose docstring tells the algorithm and its
departures from the text) with its sampling plan (``plan``), flight budget (``budget``) and
visit order (``tsp``), the analytic field (``field``), scoring against the truth (``score``), a
detector reading (``reading``) and the lawnmower baseline (``lawnmower``). The mapper is flown,
in the kinematic world too, by the missions' loop (``gcs.mission.loop_radiation``).
"""

from planners.radiation.mapper import RadiationMapper
from planners.radiation.params import Phase, RadiationMapperParams, Status
from planners.radiation.plan import fan_points, sampling_distance_m
from planners.radiation.reading import take_reading
from planners.radiation.score import Evaluation, evaluate_region
from planners.radiation.types import Decision, Hotspot, Layer, MapEstimate, RadiationResult

__all__ = [
    "Decision",
    "Evaluation",
    "Hotspot",
    "Layer",
    "MapEstimate",
    "Phase",
    "RadiationMapper",
    "RadiationMapperParams",
    "RadiationResult",
    "Status",
    "evaluate_region",
    "fan_points",
    "sampling_distance_m",
    "take_reading",
]
