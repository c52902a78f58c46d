"""The companion sensor board: its own MAVLink component (158, MAV_COMP_ID_PERIPHERAL) on the
vehicle's links, streaming the six IR proximity sensors and the radiation detector.

It streams on a link once that link has heard a GCS (any valid frame), so an idle serial port is
not flooded; it sends no HEARTBEAT, so a station that targets the first heartbeat it sees always
finds the autopilot. DISTANCE_SENSOR follows ArduPilot for out-of-range: current_distance =
max_distance + 1 cm when nothing is inside the cone and range.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from sitl.link.codec import messages
from sitl.link.view import VehicleView
from sitl.sensors.proximity import ProximityFacing

# The order the proximity model reads its sensors in, which is the cache's order.
FACINGS: tuple[int, ...] = tuple(int(f) for f in ProximityFacing)
MAV_DISTANCE_SENSOR_INFRARED = 2


@dataclass(frozen=True)
class CompanionConfig:
    """Rates and ranges of the companion board."""

    proximity_rate_hz: float = 10.0
    radiation_rate_hz: float = 5.0
    ir_min_cm: int = 2
    ir_max_cm: int = 50


class Companion:
    """Produces the companion board's frames for one vehicle."""

    def __init__(self, config: CompanionConfig | None = None) -> None:
        self.config = config or CompanionConfig()
        self._next_prox_s = 0.0
        self._next_rad_s = 0.0

    def due(self, view: VehicleView, t_s: float) -> list[Any]:
        """Messages to send at `t_s`."""
        c = self.config
        out: list[Any] = []
        boot_ms = int(t_s * 1000.0) & 0xFFFFFFFF
        if t_s + 1e-9 >= self._next_prox_s:
            self._next_prox_s = max(self._next_prox_s + 1.0 / c.proximity_rate_hz, t_s)
            for i, facing in enumerate(FACINGS):
                d = view.cache.proximity_m[i] if i < len(view.cache.proximity_m) else None
                cm = c.ir_max_cm + 1 if d is None else round(d * 100.0)
                out.append(
                    messages.MAVLink_distance_sensor_message(
                        boot_ms,
                        c.ir_min_cm,
                        c.ir_max_cm,
                        cm,
                        MAV_DISTANCE_SENSOR_INFRARED,
                        i,
                        facing,
                        0,
                        0.0,
                        0.0,
                        [0.0, 0.0, 0.0, 0.0],
                        0,
                    )
                )
        if view.has_radiation and t_s + 1e-9 >= self._next_rad_s:
            self._next_rad_s = max(self._next_rad_s + 1.0 / c.radiation_rate_hz, t_s)
            cps = view.cache.radiation_cps
            if cps is not None:
                out.append(messages.MAVLink_named_value_float_message(boot_ms, b"RAD_CPS", cps))
        return out
