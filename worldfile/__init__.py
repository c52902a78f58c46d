"""The files the simulator and the station both read (neither imports the other): the world
file's format (keys, defaults, validation, one error wording), the project's one TOML reader and
the MAVLink signing key file."""

from worldfile.placement import vehicle_start
from worldfile.schema import (
    Box,
    FieldError,
    FloorMaterial,
    FloorPatch,
    GeoOrigin,
    RadiationSource,
    Vec2,
    Vec3,
    WorldFileError,
    WorldSpec,
    load_world_file,
    parse_world,
)
from worldfile.signing_key import SigningKeyError, key_from_passphrase, load_signing_key
from worldfile.toml_file import TomlFileError, parse_toml, read_toml

__all__ = [
    "Box",
    "FieldError",
    "FloorMaterial",
    "FloorPatch",
    "GeoOrigin",
    "RadiationSource",
    "SigningKeyError",
    "TomlFileError",
    "Vec2",
    "Vec3",
    "WorldFileError",
    "WorldSpec",
    "key_from_passphrase",
    "load_signing_key",
    "load_world_file",
    "parse_toml",
    "parse_world",
    "read_toml",
    "vehicle_start",
]
