"""The poses CSV of ``holecell calibrate hand-eye``: one row per view.

Columns (header row, names exact, others ignored):

- the image: ``image`` (mono), or ``left_image`` and ``right_image`` (stereo pairs): file
  names relative to the images folder;
- the arm's pose: ``q1_rad`` ... ``q6_rad`` (joints, URDF order; used with a cell file, which
  enables the kinematic terms), or the flange pose in the base, ``x_m, y_m, z_m`` (m) and
  ``qx, qy, qz, qw`` (unit quaternion of ``R_base_tool0``).

Refused with the file and row named (row = data row, 1-based; the header is not counted):
missing columns (with a hint when one is there in other units: ``q1_deg``, ``x_mm``), a row
without an image, a value that is not a finite number, joints that look
like degrees (any beyond 2 pi), translations that look like millimetres (any beyond 5 m),
quaternions that are not of unit length.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from cell.calibration.errors import CalibrationDataError

Array = NDArray[np.float64]

JOINT_COLUMNS = tuple(f"q{i}_rad" for i in range(1, 7))
FLANGE_COLUMNS = ("x_m", "y_m", "z_m", "qx", "qy", "qz", "qw")
#: largest plausible translation of a flange in its robot's base (m): beyond, millimetres
MAX_TRANSLATION_M = 5.0
#: largest plausible joint value (rad): beyond, degrees
MAX_JOINT_RAD = 2.0 * math.pi + 1e-6
#: tolerance of a quaternion's length
QUAT_TOL = 1e-3


@dataclass(frozen=True, eq=False)
class PoseRow:
    """One view of the CSV: image names, the joints (rad) or the flange pose (4x4, m)."""

    row: int
    image: str | None
    left_image: str | None
    right_image: str | None
    q_rad: Array | None
    T_base_tool0: Array | None


def _names(cols: list[str]) -> str:
    return ", ".join(cols) if len(cols) <= 3 else f"{cols[0]}..{cols[-1]}"


def _unit_hint(missing: list[str], header: list[str]) -> str:
    """``: found q1_deg..q6_deg, ...`` when missing columns are in the header in other units."""
    stems = {c.rsplit("_", 1)[0] for c in missing if "_" in c}
    other = [h for h in header if "_" in h and h.rsplit("_", 1)[0] in stems and h not in missing]
    if not other:
        return ""
    return (
        f": found {_names(other)}, the file is in radians and metres "
        "(q1_rad, x_m): convert the values and rename the columns"
    )


def _number(text: str | None, src: str, row: int, column: str) -> float:
    try:
        v = float(text) if text is not None else math.nan
    except ValueError:
        raise CalibrationDataError(src, f"column {column}: not a number: {text!r}", row) from None
    if not math.isfinite(v):
        raise CalibrationDataError(src, f"column {column}: not a finite number: {text!r}", row)
    return v


def read_pose_csv(path: str | Path, use_joints: bool) -> tuple[PoseRow, ...]:
    """Read and check the poses CSV (see the module docstring).

    ``use_joints``: read ``q1_rad..q6_rad`` (a cell file gives the kinematics); otherwise the
    flange pose columns are required.
    """
    src = str(path)
    try:
        text = Path(path).read_text(encoding="utf-8-sig")
    except FileNotFoundError:
        raise CalibrationDataError(src, "no such file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise CalibrationDataError(src, f"cannot read: {exc}") from None
    reader = csv.DictReader(text.splitlines())
    header = [h.strip() for h in reader.fieldnames or []]
    if not header:
        raise CalibrationDataError(src, "empty file: a header row is needed")
    reader.fieldnames = header
    stereo = "left_image" in header or "right_image" in header
    image_cols = ("left_image", "right_image") if stereo else ("image",)
    pose_cols = JOINT_COLUMNS if use_joints else FLANGE_COLUMNS
    missing = [c for c in (*image_cols, *pose_cols) if c not in header]
    if missing:
        hint = _unit_hint(missing, header)
        if hint:
            raise CalibrationDataError(src, f"missing column(s) {_names(missing)}{hint}")
        if use_joints and all(c in header for c in FLANGE_COLUMNS):
            hint = " (the file gives flange poses: leave out --cell)"
        elif not use_joints and all(c in header for c in JOINT_COLUMNS):
            hint = " (the file gives joints: give the cell file with --cell)"
        raise CalibrationDataError(src, f"missing column(s) {', '.join(missing)}{hint}")
    rows = []
    for k, rec in enumerate(reader, start=1):
        if all((v or "").strip() == "" for v in rec.values() if isinstance(v, str)):
            continue
        names = {c: (rec.get(c) or "").strip() for c in image_cols}
        for c, v in names.items():
            if not v:
                raise CalibrationDataError(src, f"no image file name in column {c}", k)
        vals = np.array([_number(rec.get(c), src, k, c) for c in pose_cols])
        q, T = None, None
        if use_joints:
            worst = int(np.argmax(np.abs(vals)))
            if abs(vals[worst]) > MAX_JOINT_RAD:
                raise CalibrationDataError(
                    src,
                    f"column {pose_cols[worst]} = {vals[worst]:g}: joints are in radians, "
                    "this looks like degrees",
                    k,
                )
            q = vals
        else:
            worst = int(np.argmax(np.abs(vals[:3])))
            if abs(vals[worst]) > MAX_TRANSLATION_M:
                raise CalibrationDataError(
                    src,
                    f"column {pose_cols[worst]} = {vals[worst]:g}: translations are in metres, "
                    "this looks like millimetres",
                    k,
                )
            quat = vals[3:]
            if abs(np.linalg.norm(quat) - 1.0) > QUAT_TOL:
                raise CalibrationDataError(
                    src, f"qx..qw are not a unit quaternion (length {np.linalg.norm(quat):.6g})", k
                )
            T = np.eye(4)
            T[:3, :3] = Rotation.from_quat(quat / np.linalg.norm(quat)).as_matrix()
            T[:3, 3] = vals[:3]
        rows.append(
            PoseRow(
                row=k,
                image=names.get("image"),
                left_image=names.get("left_image"),
                right_image=names.get("right_image"),
                q_rad=q,
                T_base_tool0=T,
            )
        )
    if not rows:
        raise CalibrationDataError(src, "no data rows")
    if not use_joints:
        t = np.array([r.T_base_tool0[:3, 3] for r in rows])
        if np.abs(t).max() < 0.02 and len(rows) > 1:
            raise CalibrationDataError(
                src, "every flange translation is within 20 mm of the base: metres expected"
            )
    return tuple(rows)
