"""``cellcal.json``: the cell calibration's file (format in ``docs/calibration.md``).

:func:`save_calibration` writes it atomically; :func:`load_calibration` reads it and refuses a
malformed file naming the field; :func:`check_belongs` refuses a file of another robot, tool,
cell or stereo calibration, :func:`check_age` one older than a limit.
"""

from __future__ import annotations

import hashlib
import json
import math
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from cell.calibration.errors import CalibrationFileError
from cell.calibration.estimate.result import (
    FORMAT,
    SCHEMA_VERSION,
    CellCalibration,
    DHTermEstimate,
    PoseEstimate,
    Provenance,
    ViewResidual,
)
from robots.calibration import term_names
from robots.dh import DHTable
from robots.files import write_text_atomic

#: a calibration older than this is refused by :func:`check_age` by default (days): an arm's
#: geometry and a head's mount are re-checked monthly in a production cell
DEFAULT_MAX_AGE_DAYS = 30.0


def fingerprint(obj: Any) -> str:
    """A short stable fingerprint (16 hex digits of SHA-256) of JSON-able data."""
    text = json.dumps(obj, sort_keys=True, separators=(",", ":"), default=float)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _num(x: float) -> float | None:
    return None if not math.isfinite(x) else float(x)


def _pose(p: PoseEstimate) -> dict[str, Any]:
    return {
        "xyz": [float(v) for v in p.T[:3, 3]],
        "quat_xyzw": [float(v) for v in Rotation.from_matrix(p.T[:3, :3]).as_quat()],
        "sigma_xyz_m": [float(v) for v in p.sigma_xyz_m],
        "sigma_rot_rad": [float(v) for v in p.sigma_rot_rad],
        "covariance": p.covariance.tolist(),
    }


def _dh(table: DHTable) -> dict[str, list[float]]:
    return {
        "a_m": list(table.a_m),
        "d_m": list(table.d_m),
        "alpha_rad": list(table.alpha_rad),
        "theta_offset_rad": list(table.theta_offset_rad),
        "joint_sign": list(table.joint_sign),
    }


def calibration_to_dict(cal: CellCalibration) -> dict[str, Any]:
    """The ``cellcal.json`` dictionary (plain JSON types, SI units, NaN as null)."""
    pv = cal.provenance
    return {
        "format": FORMAT,
        "version": SCHEMA_VERSION,
        "created_utc": cal.created_utc,
        "robot": {"model": pv.robot_model, "fingerprint": pv.robot_fingerprint},
        "tool": {"fingerprint": pv.tool_fingerprint},
        "cell": {"fingerprint": pv.cell_fingerprint},
        "stereo_calibration": {"source": pv.stereo_source, "fingerprint": pv.stereo_fingerprint},
        "target": dict(cal.target),
        "T_tool0_camera": _pose(cal.T_tool0_camera),
        "T_base_target": _pose(cal.T_base_target),
        "T_left_right": None if cal.T_left_right is None else _pose(cal.T_left_right),
        "dh": {
            "nominal": None if cal.nominal_dh is None else _dh(cal.nominal_dh),
            "errors": [
                {
                    "name": t.name,
                    "value": t.value,
                    "sigma": t.sigma,
                    "free": t.free,
                    "reason": t.reason,
                }
                for t in cal.dh_terms
            ],
        },
        "parameters": {"names": list(cal.parameter_names), "covariance": cal.covariance.tolist()},
        "residuals": {
            "sigma_px": cal.sigma_px,
            "flange_scatter": dict(cal.flange_scatter),
            "rms_px": dict(cal.residual_rms_px),
            "views": [
                {
                    "name": v.name,
                    "rms_left_px": _num(v.rms_left_px),
                    "rms_right_px": _num(v.rms_right_px),
                    "n_points": v.n_points,
                }
                for v in cal.views
            ],
        },
        "counts": dict(cal.counts),
        "notes": list(cal.notes),
    }


def save_calibration(cal: CellCalibration, path: str | Path) -> None:
    """Write ``cellcal.json`` (a temporary file renamed over the target)."""
    write_text_atomic(path, json.dumps(calibration_to_dict(cal), indent=1) + "\n")


class _Reader:
    """Field access that raises :class:`CalibrationFileError` naming the field."""

    def __init__(self, path: str) -> None:
        self.path = path

    def fail(self, field: str, reason: str) -> CalibrationFileError:
        return CalibrationFileError(self.path, field, reason)

    def get(self, d: Any, key: str, field: str, kind: type | tuple[type, ...]) -> Any:
        if not isinstance(d, dict) or key not in d:
            raise self.fail(field, "missing")
        v = d[key]
        kinds = kind if isinstance(kind, tuple) else (kind,)
        if not isinstance(v, kinds) or (isinstance(v, bool) and bool not in kinds):
            names = " or ".join(k.__name__ for k in kinds)
            raise self.fail(field, f"must be {names}, got {v!r}")
        return v

    def optional_str(self, d: Any, key: str, field: str) -> str | None:
        v = self.get(d, key, field, (str, type(None)))
        return v

    def array(
        self, v: Any, field: str, shape: tuple[int, ...], allow_null: bool = False
    ) -> np.ndarray:
        try:
            arr = (
                np.array(v, dtype=float)
                if not allow_null
                else np.array([np.nan if x is None else x for x in v], dtype=float)
            )
        except (TypeError, ValueError):
            raise self.fail(field, f"must be numbers, got {v!r}"[:200]) from None
        if arr.shape != shape:
            raise self.fail(field, f"must have shape {list(shape)}, got {list(arr.shape)}")
        if not allow_null and not np.all(np.isfinite(arr)):
            raise self.fail(field, "holds non-finite values")
        return arr

    def number(self, d: Any, key: str, field: str, allow_null: bool = False) -> float:
        v = self.get(d, key, field, (int, float, type(None)) if allow_null else (int, float))
        if v is None:
            return float("nan")
        if not math.isfinite(v):
            raise self.fail(field, f"must be finite, got {v!r}")
        return float(v)

    def pose(self, d: Any, key: str) -> PoseEstimate:
        p = self.get(d, key, key, dict)
        xyz = self.array(self.get(p, "xyz", f"{key}.xyz", list), f"{key}.xyz", (3,))
        q = self.array(self.get(p, "quat_xyzw", f"{key}.quat_xyzw", list), f"{key}.quat_xyzw", (4,))
        if abs(np.linalg.norm(q) - 1.0) > 1e-6:
            raise self.fail(
                f"{key}.quat_xyzw", f"not a unit quaternion (norm {np.linalg.norm(q):.6g})"
            )
        cov = self.array(
            self.get(p, "covariance", f"{key}.covariance", list), f"{key}.covariance", (6, 6)
        )
        _covariance_ok(self, cov, f"{key}.covariance")
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = Rotation.from_quat(q).as_matrix(), xyz
        return PoseEstimate(T, cov)


def _covariance_ok(r: _Reader, cov: np.ndarray, field: str) -> None:
    if not np.allclose(cov, cov.T, rtol=1e-9, atol=1e-30):
        raise r.fail(field, "not symmetric")
    if len(cov) and np.linalg.eigvalsh(0.5 * (cov + cov.T)).min() < -1e-9 * max(
        np.abs(cov).max(), 1e-300
    ):
        raise r.fail(field, "not positive semi-definite")


def calibration_from_dict(data: Any, path: str = "<memory>") -> CellCalibration:
    """Parse a ``cellcal.json`` dictionary; raise :class:`CalibrationFileError` naming the field."""
    r = _Reader(path)
    if not isinstance(data, dict):
        raise r.fail("<root>", "must be a JSON object")
    if r.get(data, "format", "format", str) != FORMAT:
        raise r.fail("format", f"must be {FORMAT!r}, got {data['format']!r}")
    key = "version" if "version" in data or "schema_version" not in data else "schema_version"
    version = r.get(data, key, key, int)  # "schema_version": files written before Dec 2026
    if version != SCHEMA_VERSION:
        raise r.fail(key, f"this holecell reads version {SCHEMA_VERSION}, got {version}")
    created = r.get(data, "created_utc", "created_utc", str)
    try:
        datetime.strptime(created, "%Y-%m-%dT%H:%M:%SZ")
    except ValueError:
        raise r.fail("created_utc", f"must be YYYY-MM-DDTHH:MM:SSZ, got {created!r}") from None
    robot = r.get(data, "robot", "robot", dict)
    stereo = r.get(data, "stereo_calibration", "stereo_calibration", dict)
    prov = Provenance(
        robot_model=r.optional_str(robot, "model", "robot.model"),
        robot_fingerprint=r.optional_str(robot, "fingerprint", "robot.fingerprint"),
        tool_fingerprint=r.optional_str(
            r.get(data, "tool", "tool", dict), "fingerprint", "tool.fingerprint"
        ),
        cell_fingerprint=r.optional_str(
            r.get(data, "cell", "cell", dict), "fingerprint", "cell.fingerprint"
        ),
        stereo_source=r.optional_str(stereo, "source", "stereo_calibration.source"),
        stereo_fingerprint=r.optional_str(stereo, "fingerprint", "stereo_calibration.fingerprint"),
    )
    target = r.get(data, "target", "target", dict)
    for key, kind in (("kind", str), ("cols", int), ("rows", int), ("pitch_m", (int, float))):
        r.get(target, key, f"target.{key}", kind)
    dh = r.get(data, "dh", "dh", dict)
    nominal = None
    if r.get(dh, "nominal", "dh.nominal", (dict, type(None))) is not None:
        n = dh["nominal"]
        arrs = {
            k: r.array(r.get(n, k, f"dh.nominal.{k}", list), f"dh.nominal.{k}", (6,))
            for k in ("a_m", "d_m", "alpha_rad", "theta_offset_rad", "joint_sign")
        }
        nominal = DHTable(**{k: tuple(map(float, v)) for k, v in arrs.items()})
    errors = r.get(dh, "errors", "dh.errors", list)
    names = term_names()
    if errors and len(errors) != len(names):
        raise r.fail("dh.errors", f"must list all {len(names)} terms or none, got {len(errors)}")
    if errors and nominal is None:
        raise r.fail("dh.nominal", "missing: the D-H errors need the nominal table")
    terms = []
    for k, e in enumerate(errors):
        f = f"dh.errors[{k}]"
        name = r.get(e, "name", f"{f}.name", str)
        if name != names[k]:
            raise r.fail(f"{f}.name", f"must be {names[k]!r}, got {name!r}")
        terms.append(
            DHTermEstimate(
                name,
                r.number(e, "value", f"{f}.value"),
                r.number(e, "sigma", f"{f}.sigma"),
                r.get(e, "free", f"{f}.free", bool),
                r.get(e, "reason", f"{f}.reason", str),
            )
        )
    params = r.get(data, "parameters", "parameters", dict)
    pnames = r.get(params, "names", "parameters.names", list)
    if not all(isinstance(p, str) for p in pnames):
        raise r.fail("parameters.names", "must be strings")
    cov = r.array(
        r.get(params, "covariance", "parameters.covariance", list),
        "parameters.covariance",
        (len(pnames), len(pnames)),
    )
    _covariance_ok(r, cov, "parameters.covariance")
    res = r.get(data, "residuals", "residuals", dict)
    rms = r.get(res, "rms_px", "residuals.rms_px", dict)
    views = []
    for k, v in enumerate(r.get(res, "views", "residuals.views", list)):
        f = f"residuals.views[{k}]"
        views.append(
            ViewResidual(
                r.get(v, "name", f"{f}.name", str),
                r.number(v, "rms_left_px", f"{f}.rms_left_px", True),
                r.number(v, "rms_right_px", f"{f}.rms_right_px", True),
                r.get(v, "n_points", f"{f}.n_points", int),
            )
        )
    counts = r.get(data, "counts", "counts", dict)
    for key in ("views", "points", "parameters", "dof"):
        r.get(counts, key, f"counts.{key}", int)
    notes = r.get(data, "notes", "notes", list)
    return CellCalibration(
        T_tool0_camera=r.pose(data, "T_tool0_camera"),
        T_base_target=r.pose(data, "T_base_target"),
        T_left_right=None
        if r.get(data, "T_left_right", "T_left_right", (dict, type(None))) is None
        else r.pose(data, "T_left_right"),
        nominal_dh=nominal,
        dh_terms=tuple(terms),
        parameter_names=tuple(pnames),
        covariance=cov,
        sigma_px=r.number(res, "sigma_px", "residuals.sigma_px"),
        residual_rms_px={str(k): r.number(rms, k, f"residuals.rms_px.{k}") for k in rms},
        views=tuple(views),
        counts={str(k): int(v) for k, v in counts.items()},
        target=dict(target),
        provenance=prov,
        created_utc=created,
        notes=tuple(str(n) for n in notes),
        flange_scatter=_flange_scatter(r, res),
    )


def _flange_scatter(r: _Reader, res: dict) -> dict[str, object]:
    """``residuals.flange_scatter``: optional (files before it hold corner noise only)."""
    if "flange_scatter" not in res:
        return {}
    fs = r.get(res, "flange_scatter", "residuals.flange_scatter", dict)
    return {
        "sigma_m": r.number(fs, "sigma_m", "residuals.flange_scatter.sigma_m"),
        "sigma_rad": r.number(fs, "sigma_rad", "residuals.flange_scatter.sigma_rad"),
        "source": r.get(fs, "source", "residuals.flange_scatter.source", str),
    }


def load_calibration(path: str | Path) -> CellCalibration:
    """Read ``cellcal.json``; raise :class:`CalibrationFileError` naming the bad field."""
    src = str(path)
    try:
        data = json.loads(Path(path).read_text())
    except FileNotFoundError:
        raise CalibrationFileError(src, "file", "no such file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise CalibrationFileError(src, "file", f"cannot read: {exc}") from None
    except json.JSONDecodeError as exc:
        raise CalibrationFileError(src, "file", f"not valid JSON: {exc}") from None
    return calibration_from_dict(data, src)


def check_belongs(cal: CellCalibration, expected: Provenance, path: str = "<memory>") -> None:
    """Refuse a calibration of another robot, tool, cell or stereo calibration.

    Only the fingerprints ``expected`` gives (not ``None``) are compared; a file that lacks
    one of them (offline data without a cell file) is refused too.
    """
    for field, want, have in (
        ("robot.fingerprint", expected.robot_fingerprint, cal.provenance.robot_fingerprint),
        ("tool.fingerprint", expected.tool_fingerprint, cal.provenance.tool_fingerprint),
        ("cell.fingerprint", expected.cell_fingerprint, cal.provenance.cell_fingerprint),
        (
            "stereo_calibration.fingerprint",
            expected.stereo_fingerprint,
            cal.provenance.stereo_fingerprint,
        ),
    ):
        if want is not None and have != want:
            what = field.split(".")[0].replace("_", " ")
            raise CalibrationFileError(
                path, field, f"belongs to another {what} ({have} here, {want} expected)"
            )


def check_age(
    cal: CellCalibration,
    max_age_days: float = DEFAULT_MAX_AGE_DAYS,
    now: datetime | None = None,
    path: str = "<memory>",
) -> None:
    """Refuse a calibration made more than ``max_age_days`` before ``now`` (UTC)."""
    made = datetime.strptime(cal.created_utc, "%Y-%m-%dT%H:%M:%SZ").replace(tzinfo=UTC)
    age = ((now or datetime.now(UTC)) - made).total_seconds() / 86400.0
    if age > max_age_days:
        raise CalibrationFileError(
            path,
            "created_utc",
            f"made {age:.1f} days ago, older than the limit of {max_age_days:g} days: "
            "calibrate again",
        )
