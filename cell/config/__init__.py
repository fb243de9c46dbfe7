"""The cell file (``cell.yaml``): robot, stereo head, part with holes, obstacles, reference targets.

Every length is in metres, every angle in radians. Poses are
``{xyz: [...], rpy: [...]}`` or ``{xyz: [...], quat_xyzw: [...]}``. The part's
holes and obstacles are given in the part frame, placed in the cell by
``part.base``; environment obstacles and reference targets are in the cell
frame. :func:`load_cell` validates the whole file and reports every problem
with the file name, the field path and the value.
"""

from __future__ import annotations

from cell.config.load import (
    BUILTIN_CELLS,
    DATA_DIR,
    builtin_cell_path,
    load_builtin_cell,
    load_cell,
    parse_cell,
)
from cell.config.pose import (
    IDENTITY,
    UNIT_TOL,
    Pose,
    Positive,
    Vec3,
)
from cell.config.schema import (
    PART_TEMPERATURE_RANGE_C,
    CalibrationTarget,
    CellConfig,
    Environment,
    Hole,
    HoleInCell,
    JointRange,
    Limits,
    Part,
    ReferenceTarget,
    Robot,
    Tool,
)
from cell.config.shapes import (
    SHAPE_KINDS,
    Box,
    Cylinder,
    ShapeSpec,
    Sphere,
)

__all__ = [
    "BUILTIN_CELLS",
    "DATA_DIR",
    "IDENTITY",
    "PART_TEMPERATURE_RANGE_C",
    "SHAPE_KINDS",
    "UNIT_TOL",
    "Box",
    "CalibrationTarget",
    "CellConfig",
    "Cylinder",
    "Environment",
    "Hole",
    "HoleInCell",
    "JointRange",
    "Limits",
    "Part",
    "Pose",
    "Positive",
    "ReferenceTarget",
    "Robot",
    "ShapeSpec",
    "Sphere",
    "Tool",
    "Vec3",
    "builtin_cell_path",
    "load_builtin_cell",
    "load_cell",
    "parse_cell",
]
