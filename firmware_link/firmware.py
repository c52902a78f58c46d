"""Which firmware is on the other end, from what the vehicle itself says (pure, no I/O).

Sources, most trusted first:
1. AUTOPILOT_VERSION: the firmware's own version number (ArduCopter 4.x answers
   MAV_CMD_REQUEST_MESSAGE / MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES; 3.2.1 does not).
2. The parameter set: `MAV_GCS_SYSID` exists from 4.7 on (it replaced `SYSID_MYGCS`),
   `MOT_THST_HOVER` on every 4.x, `THR_MID` only on 3.x (4.x learns the hover throttle instead).
3. The STATUSTEXT version banner, e.g. "ArduCopter V3.2.1" (3.2.1 sends it in reply to
   PARAM_REQUEST_LIST) or "ArduCopter V4.7.0-dev (d2e4299f)".
4. The wire version of the first frame, only as a hint: a 4.x port can be set to MAVLink 1, so
   a MAVLink 1 frame alone does not make an APM 2.5.

`FirmwareEvidence` collects what was heard; `decide_firmware` turns it into a `FirmwareInfo`
whose `evidence` lines say what was found and why the verdict follows.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Any

from firmware_link.protocol import WireVersion
from firmware_link.records import Dialect

GCS_ID_OLD = "SYSID_MYGCS"
GCS_ID_NEW = "MAV_GCS_SYSID"  # ArduCopter 4.7 renamed SYSID_MYGCS
HOVER_4X = "MOT_THST_HOVER"
THR_MID_3X = "THR_MID"
PROBE_PARAMS = (GCS_ID_OLD, GCS_ID_NEW, THR_MID_3X, HOVER_4X)
# FIRMWARE_VERSION_TYPE in the low byte of flight_sw_version
_RELEASE_SUFFIX = {0: "-dev", 64: "-alpha", 128: "-beta", 192: "-rc", 255: ""}
# MAV_TYPE values ArduCopter reports (quad, coaxial, heli, hexa, octo, tri, dodeca, deca)
_COPTER_TYPES = frozenset({2, 3, 4, 13, 14, 15, 29, 35})
_BANNER = re.compile(
    r"^(?P<name>ArduCopter|APM:Copter|ArduPilot Copter)\s+V(?P<ver>(?P<major>\d+)\.(?P<minor>\d+)"
    r"\.(?P<patch>\d+)(?P<suffix>[-\w.]*))"
)


@dataclass(frozen=True, slots=True)
class FirmwareInfo:
    """The firmware of the vehicle, and the evidence it was told by.

    `version` is the firmware's own text ("ArduCopter V3.2.1", "ArduCopter V4.7.0-dev"), empty
    when the vehicle never said; `wire` is the MAVLink version the vehicle speaks on this port,
    which is what the station must send, whatever the firmware family.
    """

    dialect: Dialect
    version: str
    gcs_sysid_param: str  # the parameter naming the GCS the vehicle obeys
    wire: WireVersion
    evidence: tuple[str, ...]
    version_number: tuple[int, int, int] | None = None
    # what told `name`: "AUTOPILOT_VERSION", "STATUSTEXT banner", "parameters: THR_MID",
    # "heartbeat only: MAVLink 1 frames"; "" before anything was heard
    source: str = ""

    @property
    def name(self) -> str:
        """The version text, or the family when the vehicle gave no version."""
        family = {Dialect.APM25: "ArduCopter 3.x", Dialect.COPTER4: "ArduCopter 4.x"}
        return self.version or family.get(self.dialect, "unknown firmware")

    @property
    def label(self) -> str:
        """The name and how it was told, as a pilot reads it: "ArduCopter V4.7.0-dev
        (AUTOPILOT_VERSION)", "ArduCopter 3.x (parameters: THR_MID)"."""
        return f"{self.name} ({self.source})" if self.source else self.name

    @property
    def summary(self) -> str:
        """One line: version (or family), dialect, wire, GCS-id parameter, the source."""
        given = "" if self.version else " (no version given)"
        told = f"; identified by {self.source}" if self.source else ""
        return (
            f"{self.name}{given}: dialect {self.dialect.name}, MAVLink {int(self.wire)} on this "
            f"port, GCS id in {self.gcs_sysid_param}{told}"
        )


def decode_sw_version(flight_sw_version: int) -> tuple[int, int, int, str]:
    """AUTOPILOT_VERSION.flight_sw_version → (major, minor, patch, suffix such as "-dev")."""
    v = int(flight_sw_version)
    kind = v & 0xFF
    suffix = _RELEASE_SUFFIX.get(kind, f"-type{kind}")
    return (v >> 24) & 0xFF, (v >> 16) & 0xFF, (v >> 8) & 0xFF, suffix


def parse_banner(text: str) -> tuple[str, tuple[int, int, int]] | None:
    """("ArduCopter V3.2.1", (3, 2, 1)) from a version banner STATUSTEXT; None otherwise."""
    m = _BANNER.match(text.strip())
    if m is None:
        return None
    number = (int(m["major"]), int(m["minor"]), int(m["patch"]))
    return f"ArduCopter V{m['ver']}", number


@dataclass
class FirmwareEvidence:
    """What the vehicle said so far; filled by the link as frames arrive."""

    wire: WireVersion | None = None
    mav_type: int | None = None
    sw_version: int | None = None
    git_hash: str = ""
    banner: str = ""
    params_seen: set[str] = field(default_factory=set)
    params_missing: set[str] = field(default_factory=set)  # asked for, never answered
    version_refused: bool = False  # AUTOPILOT_VERSION asked for and refused/unanswered

    def first_frame(self, frame: bytes, mav_type: int) -> None:
        """The vehicle's first heartbeat: its wire version and airframe type."""
        self.wire = WireVersion.V1 if frame[:1] == b"\xfe" else WireVersion.V2
        self.mav_type = mav_type

    def autopilot_version(self, msg: Any) -> None:
        """An AUTOPILOT_VERSION message."""
        self.sw_version = int(msg.flight_sw_version)
        raw = bytes(bytearray(msg.flight_custom_version))
        self.git_hash = raw.split(b"\x00", 1)[0].decode("ascii", "replace")

    def statustext(self, text: str) -> None:
        """A STATUSTEXT: kept when it is the version banner."""
        if parse_banner(text) is not None:
            self.banner = text.strip()

    def param_seen(self, name: str) -> None:
        """A PARAM_VALUE of `name` arrived."""
        self.params_seen.add(name)
        self.params_missing.discard(name)


def _name_from_version(number: tuple[int, int, int] | None) -> str:
    return GCS_ID_NEW if number is not None and number[:2] >= (4, 7) else GCS_ID_OLD


def decide_firmware(ev: FirmwareEvidence) -> FirmwareInfo:
    """The verdict on the evidence, trusting the sources in the module docstring's order."""
    notes: list[str] = []
    wire = ev.wire or WireVersion.V2
    dialect = Dialect.UNKNOWN
    version = ""
    source = ""
    number: tuple[int, int, int] | None = None
    seen = ev.params_seen
    name = "ArduCopter" if ev.mav_type is None or ev.mav_type in _COPTER_TYPES else "ArduPilot"

    if ev.sw_version is not None:
        major, minor, patch, suffix = decode_sw_version(ev.sw_version)
        number = (major, minor, patch)
        version = f"{name} V{major}.{minor}.{patch}{suffix}"
        dialect = Dialect.COPTER4 if major >= 4 else Dialect.APM25
        source = "AUTOPILOT_VERSION"
        git = f", git {ev.git_hash}" if ev.git_hash else ""
        notes.append(f"AUTOPILOT_VERSION: {version}{git} ⇒ {dialect.name}")
    elif ev.version_refused:
        notes.append("AUTOPILOT_VERSION not answered (ArduCopter 3.2.1 has no such reply)")

    by_params = Dialect.UNKNOWN
    if GCS_ID_NEW in seen:
        by_params = Dialect.COPTER4
        notes.append(f"parameter {GCS_ID_NEW} exists ⇒ ArduCopter 4.7 or later")
    elif HOVER_4X in seen:
        by_params = Dialect.COPTER4
        notes.append(f"parameter {HOVER_4X} exists ⇒ ArduCopter 4.x")
    if THR_MID_3X in seen:
        if by_params is Dialect.COPTER4:
            notes.append(f"parameter {THR_MID_3X} also exists (not a 4.x name): ignored")
        else:
            by_params = Dialect.APM25
            notes.append(f"parameter {THR_MID_3X} exists ⇒ ArduCopter 3.x")
    absent = sorted(n for n in ev.params_missing if n in PROBE_PARAMS)
    if absent:
        notes.append(f"no such parameter: {', '.join(absent)}")
    if dialect is Dialect.UNKNOWN:
        dialect = by_params
        if by_params is not Dialect.UNKNOWN:
            told = sorted(seen & {GCS_ID_NEW, HOVER_4X, THR_MID_3X})
            source = f"parameters: {', '.join(told)}"
    elif by_params not in (Dialect.UNKNOWN, dialect):
        notes.append(f"the parameters suggest {by_params.name}; AUTOPILOT_VERSION is trusted")

    banner = parse_banner(ev.banner) if ev.banner else None
    if banner is not None:
        text, b_number = banner
        b_dialect = Dialect.COPTER4 if b_number[0] >= 4 else Dialect.APM25
        notes.append(f"version banner {ev.banner!r}")
        if not version:
            version, number = text, b_number
            source = "STATUSTEXT banner"
        if dialect is Dialect.UNKNOWN:
            dialect = b_dialect
            notes.append(f"the banner ⇒ {b_dialect.name}")
        elif b_dialect is not dialect:
            notes.append(f"the banner suggests {b_dialect.name}; stronger evidence is trusted")

    hint = Dialect.APM25 if wire is WireVersion.V1 else Dialect.COPTER4
    if ev.wire is not None:
        if dialect is Dialect.UNKNOWN:
            dialect = hint
            source = f"heartbeat only: MAVLink {int(wire)} frames"
            notes.append(
                f"only the wire version: MAVLink {int(wire)} frames ⇒ {hint.name} (a hint)"
            )
        elif dialect is Dialect.COPTER4 and wire is WireVersion.V1:
            notes.append(
                "MAVLink 1 frames from a 4.x vehicle: a port set to MAVLink 1, not an APM 2.5"
            )
        else:
            notes.append(f"MAVLink {int(wire)} frames, as {dialect.name} speaks")

    if GCS_ID_NEW in seen:
        gcs_param = GCS_ID_NEW
    elif GCS_ID_OLD in seen:
        gcs_param = GCS_ID_OLD
    else:
        gcs_param = _name_from_version(number)
        notes.append(f"GCS-id parameter {gcs_param} assumed (neither name was read)")
    return FirmwareInfo(
        dialect=dialect,
        version=version,
        gcs_sysid_param=gcs_param,
        wire=wire,
        evidence=tuple(notes),
        version_number=number,
        source=source,
    )
