"""What is in a recording: duration, topics, counts, rates, largest gaps and link losses."""

from __future__ import annotations

import datetime as dt
import re
from dataclasses import asdict, dataclass
from typing import Any

from logs.reader import Recording
from logs.topics import EVENTS_TOPIC, LINK_EVENTS_TOPIC, LOG_TOPIC

_LOST_TEXT = re.compile(r"^\s*LOST\b|\blink (was )?lost\b", re.IGNORECASE)


@dataclass(frozen=True, slots=True)
class TopicSummary:
    """One topic's traffic: count, mean rate and its largest inter-message gap."""

    topic: str
    schema_name: str
    count: int
    rate_hz: float
    max_gap_s: float
    max_gap_at_s: float  # seconds from the recording's start to where the gap began


@dataclass(frozen=True, slots=True)
class LinkLoss:
    """A link-loss event found in the recording."""

    at_s: float  # from the recording's start
    topic: str
    text: str


@dataclass(frozen=True, slots=True)
class RecordingSummary:
    """Everything `quadgcs logs info` reports."""

    path: str
    start_utc: str
    duration_s: float
    messages: int
    vehicle: str
    software_version: str
    connection: str
    truncated: bool
    topics: tuple[TopicSummary, ...]
    link_losses: tuple[LinkLoss, ...]

    def to_dict(self) -> dict[str, Any]:
        """Plain data for `--json`."""
        return asdict(self)


def _is_loss(topic: str, message: dict[str, Any]) -> str | None:
    """The text of a link-loss event, or None: a LinkEvent of kind "lost", or a log line."""
    if str(message.get("kind", "")).lower() == "lost":
        return str(message.get("detail", "lost"))
    text = message.get("message", message.get("text"))
    if isinstance(text, str) and _LOST_TEXT.search(text):
        return text
    return None


def summarize(recording: Recording) -> RecordingSummary:
    """Read the recording once and summarise it."""
    start_ns = recording.start_ns
    info = recording.topic_info
    first: dict[str, int] = {}
    last: dict[str, int] = {}
    gap: dict[str, tuple[int, int]] = {}
    for topic, log_ns, _data in recording.raw_messages():
        prev = last.get(topic)
        if prev is None:
            first[topic] = log_ns
        else:
            d = log_ns - prev
            if d > gap.get(topic, (-1, 0))[0]:
                gap[topic] = (d, prev)
        last[topic] = log_ns
    # The link's own events are the best witness; the station's and the log lines repeat them,
    # so the first of these topics that reports any loss is the one counted.
    by_topic: dict[str, list[LinkLoss]] = {}
    event_topics = [
        t
        for t in (LINK_EVENTS_TOPIC, EVENTS_TOPIC, LOG_TOPIC)
        if t in recording.counts and info[t].message_encoding == "json"
    ]
    if event_topics:
        for topic, log_ns, message in recording.messages(event_topics):
            text = _is_loss(topic, message)
            if text is not None:
                loss = LinkLoss((log_ns - start_ns) / 1e9, topic, text)
                by_topic.setdefault(topic, []).append(loss)
    losses = next((by_topic[t] for t in event_topics if by_topic.get(t)), [])
    rows = []
    for topic, topic_info in info.items():
        n = topic_info.count
        span_s = (last.get(topic, 0) - first.get(topic, 0)) / 1e9
        d, at = gap.get(topic, (0, first.get(topic, start_ns)))
        rows.append(
            TopicSummary(
                topic=topic,
                schema_name=topic_info.schema_name,
                count=n,
                rate_hz=(n - 1) / span_s if n > 1 and span_s > 0 else 0.0,
                max_gap_s=d / 1e9,
                max_gap_at_s=(at - start_ns) / 1e9 if n > 1 else 0.0,
            )
        )
    meta = recording.metadata
    start = dt.datetime.fromtimestamp(start_ns / 1e9, tz=dt.UTC) if start_ns else None
    return RecordingSummary(
        path=str(recording.path),
        start_utc=start.isoformat(timespec="milliseconds").replace("+00:00", "Z") if start else "",
        duration_s=recording.duration_s,
        messages=sum(recording.counts.values()),
        vehicle=str(meta.get("vehicle", "")),
        software_version=str(meta.get("software_version", "")),
        connection=str(meta.get("connection", meta.get("url", ""))),
        truncated=recording.truncated,
        topics=tuple(rows),
        link_losses=tuple(losses),
    )


def format_summary(summary: RecordingSummary) -> str:
    """A readable table."""
    lines = [
        f"file      {summary.path}" + ("  (truncated: whole chunks only)" * summary.truncated),
        f"start     {summary.start_utc or '-'}",
        f"duration  {summary.duration_s:.1f} s   messages {summary.messages}",
    ]
    if summary.vehicle or summary.connection:
        lines.append(
            f"vehicle   {summary.vehicle or '-'}   connection {summary.connection or '-'}   "
            f"software {summary.software_version or '-'}"
        )
    width = max([len("topic"), *(len(t.topic) for t in summary.topics)])
    schema_w = max([len("schema"), *(len(t.schema_name) for t in summary.topics)])
    lines.append("")
    lines.append(
        f"{'topic':<{width}}  {'schema':<{schema_w}}  {'count':>8}  {'rate Hz':>8}  "
        f"{'max gap s':>9}  {'at s':>8}"
    )
    for t in summary.topics:
        lines.append(
            f"{t.topic:<{width}}  {t.schema_name:<{schema_w}}  {t.count:>8}  {t.rate_hz:>8.1f}  "
            f"{t.max_gap_s:>9.3f}  {t.max_gap_at_s:>8.1f}"
        )
    lines.append("")
    if summary.link_losses:
        lines.append(f"link losses: {len(summary.link_losses)}")
        for loss in summary.link_losses:
            lines.append(f"  {loss.at_s:8.1f} s  {loss.topic}  {loss.text}")
    else:
        lines.append("link losses: none")
    return "\n".join(lines)
