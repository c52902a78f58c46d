"""The world-file format, read alike by the simulator and the station (neither imports the
other): keys, defaults, validation, one error wording; the one TOML reader of the project."""

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
from worldfile.toml_file import TomlFileError, parse_toml, read_toml

__all__ = [
    "Box",
    "FieldError",
    "FloorMaterial",
    "FloorPatch",
    "GeoOrigin",
    "RadiationSource",
    "TomlFileError",
    "Vec2",
    "Vec3",
    "WorldFileError",
    "WorldSpec",
    "load_world_file",
    "parse_toml",
    "parse_world",
    "read_toml",
    "vehicle_start",
]
