"""Feeds the teleop screens from a recorded flight: the same panels, driven by a `Player`.

The player is a pure scheduler; this backend asks it for the messages that are due each time
the screen redraws, folds them into the latest values and histories, and builds the same
`TeleopView` a live station gives. Intents other than play/pause, speed and seek are ignored:
a recording cannot be flown.
"""

from __future__ import annotations

import math
from collections import deque
from typing import Any

from firmware_link.records import FlightMode
from gcs import topics
from gcs.pilot import intents
from gcs.pilot.view import AltitudeView, LinkView, LoopView, TeleopView, VehicleView
from logs.replay import Player, ReplayMessage

HISTORY_POINTS = 300
PLOT_EVERY_S = 0.1
MODE_NAMES = {m.value: m.name for m in FlightMode}
SPEED_RANGE = (0.125, 64.0)


class ReplayBackend:
    """A `TeleopBackend` over a recording."""

    live = False

    def __init__(self, player: Player, *, name: str = "", metadata: dict[str, Any] | None = None,
                 start_playing: bool = True) -> None:
        self.player = player
        self.name = name
        self.metadata = metadata or {}
        self._latest: dict[str, dict[str, Any]] = {}
        self._alt: deque[tuple[float, float | None, float | None, float | None]] = deque(
            maxlen=HISTORY_POINTS)
        self._acc: deque[tuple[float, float | None]] = deque(maxlen=HISTORY_POINTS)
        self._messages: deque[tuple[float, str]] = deque(maxlen=200)
        self._next_plot_s = -math.inf
        self._t_s = 0.0
        self._truth_m: float | None = None
        if start_playing:
            player.play()

    def _absorb(self, msg: ReplayMessage) -> None:
        self._latest[msg.topic] = msg.message
        self._t_s = msg.t_s
        if msg.topic == topics.SIM_TRUTH:
            # SIMSTATE carries no altitude (NaN, written as null); SIM_STATE does
            down = _down_m(msg.message.get("pos_n"))
            if down is not None:
                self._truth_m = -down
        if msg.topic in (topics.EVENTS, topics.STATUS_TEXT):
            self._messages.append((msg.t_s, str(msg.message.get("text", ""))))
        elif msg.topic == topics.LINK_EVENT:
            self._messages.append(
                (msg.t_s, f"link {msg.message.get('kind')}: {msg.message.get('detail', '')}"))
        elif msg.topic == topics.ESTIMATE and msg.t_s >= self._next_plot_s:
            self._next_plot_s = msg.t_s + PLOT_EVERY_S
            ctrl = self._latest.get(topics.ALT_CONTROLLER)
            sonar = self._latest.get(topics.RANGEFINDER)
            self._alt.append((
                msg.t_s,
                msg.message.get("alt_m"),
                ctrl.get("setpoint_m") if ctrl else None,
                sonar.get("distance_m") if sonar and sonar.get("valid") else None,
            ))
            self._acc.append((msg.t_s, msg.message.get("acc_mps2")))

    def view(self) -> TeleopView:
        """Advance the player to now and build the view."""
        for msg in self.player.due():
            self._absorb(msg)
        get = self._latest.get
        hb, att, est = get(topics.HEARTBEAT), get(topics.ATTITUDE), get(topics.ESTIMATE)
        batt, sonar = get(topics.BATTERY), get(topics.RANGEFINDER)
        ctrl, rc, loop = get(topics.ALT_CONTROLLER), get(topics.RC_OVERRIDE), get(topics.LOOP)
        state = "▶" if self.player.playing else "❚❚"
        if self.player.finished:
            state = "■"
        return TeleopView(
            t_s=self._t_s,
            link=LinkView(url=self.name, dialect=str(self.metadata.get("profile", "")),
                          connected=hb is not None, recording=self.name),
            vehicle=VehicleView(
                mode=MODE_NAMES.get(int(hb["mode"]), str(hb["mode"])) if hb else "",
                armed=bool(hb and hb.get("armed")),
                failsafe=bool(hb and int(hb.get("system_status", 0)) >= 5),
                battery_v=batt.get("voltage_v") if batt else None,
                battery_pct=batt.get("remaining_pct") if batt else None,
                roll_deg=math.degrees(att["roll_rad"]) if att else None,
                pitch_deg=math.degrees(att["pitch_rad"]) if att else None,
                yaw_deg=math.degrees(att["yaw_rad"]) if att else None,
            ),
            altitude=AltitudeView(
                sonar_m=sonar["distance_m"] if sonar and sonar.get("valid") else None,
                fused_m=est.get("alt_m") if est else None,
                setpoint_m=ctrl.get("setpoint_m") if ctrl else None,
                climb_mps=est.get("vel_mps") if est else None,
                acc_up_mps2=est.get("acc_mps2") if est else None,
                truth_m=self._truth_m,
                hold_on=ctrl is not None,
                throttle_us=int(rc["throttle_us"]) if rc else None,
            ),
            loop=LoopView(
                period_ms=loop.get("period_ms") if loop else None,
                compute_ms=loop.get("compute_ms") if loop else None,
                ticks=int(loop.get("tick", 0)) if loop else 0,
            ),
            alt_history=tuple(self._alt),
            acc_history=tuple(self._acc),
            messages=tuple(self._messages),
            replay=f"{state} {self.player.speed:g}x {self.player.position_s:.1f}/"
                   f"{self.player.duration_s:.1f} s",
        )

    def send(self, intent: intents.Intent) -> None:
        """Play/pause, speed and seek; anything else means nothing on a recording."""
        p = self.player
        match intent:
            case intents.TogglePause():
                if p.playing:
                    p.pause()
                else:
                    p.play()
            case intents.ScaleSpeed(factor=f):
                p.speed = min(max(p.speed * f, SPEED_RANGE[0]), SPEED_RANGE[1])
            case intents.Seek(delta_s=d):
                p.seek(min(max(p.position_s + d, 0.0), p.duration_s))
            case _:
                pass

    def close(self) -> None:
        """Nothing to release: the recording is read-only."""


def _down_m(vec: object) -> float | None:
    """The z (down) part of a recorded vector: {"x","y","z"} as written, or a 3-list."""
    z = vec.get("z") if isinstance(vec, dict) else (
        vec[2] if isinstance(vec, list | tuple) and len(vec) == 3 else None)
    return float(z) if isinstance(z, int | float) and math.isfinite(z) else None
