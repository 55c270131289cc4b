"""Vessels: the containers the disks move in, one module per shape.

Every shape is a `Vessel` (`base.py`): it answers the geometry that placement, the audit, the
observers, the files and the views need (inside test, outline, area open to centres, named walls
and their contact lengths, bounding box). Adding a shape means adding its module and registering
its class in `VESSELS`.
"""

from __future__ import annotations

from typing import Any

from collidium.errors import InputError
from collidium.vessels.base import OUTSIDE_TOLERANCE, Vessel
from collidium.vessels.box import Box
from collidium.vessels.circle import Circle
from collidium.vessels.partitions import Partition, partition_from_dict
from collidium.vessels.polygon import Polygon, regular_polygon
from collidium.vessels.walls import (
    Inelastic,
    Piston,
    Specular,
    Thermal,
    WallResponse,
    response_from_dict,
)

#: Vessel classes by their `Vessel.kind` (the ``shape`` of a scenario file or checkpoint).
VESSELS: dict[str, type[Vessel]] = {cls.kind: cls for cls in (Box, Circle, Polygon)}


def vessel_from_dict(data: dict[str, Any]) -> Vessel:
    """The vessel of `Vessel.to_dict`'s output: ``{"shape": kind, **parameters, "walls": ...,
    "partitions": [...]}``."""
    parameters = dict(data)
    shape = parameters.pop("shape", "box")
    if shape not in VESSELS:
        raise InputError("vessel.shape", f"must be one of {tuple(VESSELS)}, got {shape!r}")
    walls: dict[str, WallResponse] = {
        name: response_from_dict(response, f"vessel.walls.{name}")
        for name, response in parameters.pop("walls", {}).items()
    }
    listed = parameters.pop("partitions", [])
    if not isinstance(listed, list):
        raise InputError("vessel.partitions", f"must be a list of tables, got {listed!r}")
    partitions = [partition_from_dict(item, k) for k, item in enumerate(listed)]
    return VESSELS[shape](**parameters, walls=walls, partitions=partitions)


__all__ = [
    "OUTSIDE_TOLERANCE",
    "VESSELS",
    "Box",
    "Circle",
    "Inelastic",
    "Partition",
    "Piston",
    "Polygon",
    "Specular",
    "Thermal",
    "Vessel",
    "WallResponse",
    "regular_polygon",
    "vessel_from_dict",
]
