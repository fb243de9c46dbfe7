"""``thermal.json``: an identified thermal model with its uncertainty and fit report.

Layout (SI units; temperatures in degC)::

    {"format": "holecell.thermal", "version": 1, "robot_model": "abb_irb2600_20_165",
     "dh": {"a_m": [...6], "d_m": [...6], "alpha_rad": [...6], "theta_offset_rad": [...6]},
            (and "joint_sign": [...6] of +1/-1 when a joint turns about -z_{i-1}, e.g. KUKA's J1)
     "sensors": {"names": ["j1", ...], "reference_degC": [...], "link_sensors": [...6 names]},
     "terms": {"lengths": true, "offsets": false},
     "coefficients": {"k_link2": {"value": 2.3e-05, "std": 4e-07, "unit": "1/K"}, ...},
     "refused": {"k_link5": "link 5 has no D-H length (a5 = d5 = 0)"},
     "T_cell_base": {"xyz": [...], "quat_xyzw": [...]}, "T_tool0_tcp": {...},
     "fit": {"residual_rms_m": ..., "rank": ..., "condition": ..., ...},
     "covariance": {"terms": ["k_link1", ...], "matrix": [[...], ...]}}

``covariance`` (optional; files written before it existed have only each term's ``std``) is the
full covariance of the identified terms in SI units squared ((1/K)^2, (rad/K)^2), rows and columns
in the order of ``terms``; :meth:`robots.thermal.ThermalModel.predict_covariance` propagates it
to a TCP position covariance.
"""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from robots.dh import DHTable
from robots.files import write_text_atomic
from robots.thermal.errors import ThermalError, ThermalModelFileError
from robots.thermal.model import TERM_UNIT, ThermalModel, ThermalSpec, term_kind_and_link
from robots.transforms import matrix_to_pose, pose_to_matrix

FORMAT = "holecell.thermal"
FORMAT_VERSION = 1
#: the tag of files written before format + version (still read)
LEGACY_FORMAT = "holecell.thermal/1"


def model_to_dict(model: ThermalModel) -> dict[str, Any]:
    """The JSON-ready description of a model."""
    spec = model.spec
    a, d, alpha, theta = model.table.arrays()

    def pose(T: np.ndarray) -> dict[str, list[float]]:
        p = matrix_to_pose(T)
        return {"xyz": p["xyz"], "quat_xyzw": p["quat_xyzw"]}

    return {
        "format": FORMAT,
        "version": FORMAT_VERSION,
        "robot_model": model.robot_model,
        "dh": {
            "a_m": a.tolist(),
            "d_m": d.tolist(),
            "alpha_rad": alpha.tolist(),
            "theta_offset_rad": theta.tolist(),
            **(
                {"joint_sign": list(model.table.joint_sign)}
                if -1.0 in model.table.joint_sign
                else {}
            ),
        },
        "sensors": {
            "names": list(spec.sensor_names),
            "reference_degC": list(spec.reference_degC),
            "link_sensors": [spec.sensor_names[i] for i in spec.sensor_of_link],
        },
        "terms": {"lengths": spec.lengths, "offsets": spec.offsets},
        "coefficients": {
            name: {
                "value": float(value),
                "std": float(model.std.get(name, math.nan)),
                "unit": TERM_UNIT[term_kind_and_link(name)[0]],
            }
            for name, value in model.coefficients.items()
        },
        "refused": dict(model.refused),
        "T_cell_base": pose(model.T_cell_base),
        "T_tool0_tcp": pose(model.T_tool0_tcp),
        "fit": {k: float(v) for k, v in model.fit.items()},
        **(
            {}
            if model.covariance is None
            else {
                "covariance": {
                    "terms": list(model.coefficients),
                    "matrix": np.asarray(model.covariance, float).tolist(),
                }
            }
        ),
    }


def save_model(path: str | Path, model: ThermalModel) -> None:
    """Write ``thermal.json`` (NaN uncertainties become null)."""
    text = json.dumps(model_to_dict(model), indent=2)
    write_text_atomic(path, text.replace("NaN", "null") + "\n")


def _get(doc: dict[str, Any], path: str, src: str) -> Any:
    node: Any = doc
    for key in path.split("."):
        if not isinstance(node, dict) or key not in node:
            raise ThermalModelFileError(src, path, "missing")
        node = node[key]
    return node


def _vector(doc: dict[str, Any], path: str, src: str, n: int | None = None) -> list[float]:
    value = _get(doc, path, src)
    try:
        out = [float(v) for v in value]
    except (TypeError, ValueError):
        raise ThermalModelFileError(
            src, path, f"expected a list of numbers, got {value!r}"
        ) from None
    if (n is not None and len(out) != n) or not all(math.isfinite(v) for v in out):
        raise ThermalModelFileError(
            src, path, f"expected {n or 'some'} finite numbers, got {value!r}"
        )
    return out


def _pose(doc: dict[str, Any], path: str, src: str) -> np.ndarray:
    return pose_to_matrix(
        _vector(doc, f"{path}.xyz", src, 3), quat_xyzw=_vector(doc, f"{path}.quat_xyzw", src, 4)
    )


def _covariance(doc: dict[str, Any], names: tuple[str, ...], src: str) -> np.ndarray | None:
    """The optional covariance block, reordered to ``names`` (the coefficients' order)."""
    if doc.get("covariance") is None:
        return None
    terms = [str(t) for t in _get(doc, "covariance.terms", src)]
    if sorted(terms) != sorted(names) or len(set(terms)) != len(terms):
        raise ThermalModelFileError(
            src, "covariance.terms", f"{terms} do not match the coefficients {list(names)}"
        )
    rows = _get(doc, "covariance.matrix", src)
    n = len(terms)
    if not isinstance(rows, list) or len(rows) != n:
        raise ThermalModelFileError(src, "covariance.matrix", f"expected {n} rows of {n} numbers")
    M = np.array([_row(r, i, n, src) for i, r in enumerate(rows)]).reshape(n, n)
    scale = np.sqrt(np.abs(np.outer(np.diag(M), np.diag(M)))) + 1e-300
    if np.any(np.diag(M) < 0) or np.max(np.abs(M - M.T) / scale) > 1e-6:
        raise ThermalModelFileError(
            src, "covariance.matrix", "must be symmetric with a non-negative diagonal"
        )
    order = [terms.index(nm) for nm in names]
    return M[np.ix_(order, order)]


def _row(row: Any, i: int, n: int, src: str) -> list[float]:
    try:
        out = [float(v) for v in row]
    except (TypeError, ValueError):
        out = []
    if len(out) != n or not all(math.isfinite(v) for v in out):
        raise ThermalModelFileError(
            src, f"covariance.matrix[{i}]", f"expected {n} finite numbers, got {row!r}"
        )
    return out


def model_from_dict(doc: Any, src: str = "thermal.json") -> ThermalModel:
    """A model from its JSON description; raises :class:`ThermalModelFileError` naming the field."""
    if not isinstance(doc, dict) or doc.get("format") not in (FORMAT, LEGACY_FORMAT):
        found = doc.get("format") if isinstance(doc, dict) else type(doc).__name__
        raise ThermalModelFileError(src, "format", f"expected {FORMAT!r}, found {found!r}")
    if doc["format"] == FORMAT and doc.get("version") != FORMAT_VERSION:
        raise ThermalModelFileError(
            src,
            "version",
            f"this holecell reads version {FORMAT_VERSION}, found {doc.get('version')!r}",
        )
    rows = ("a_m", "d_m", "alpha_rad", "theta_offset_rad")
    table = DHTable(*(tuple(_vector(doc, f"dh.{k}", src, 6)) for k in rows))
    if "joint_sign" in _get(doc, "dh", src):  # written only for arms with a -1
        sign = tuple(_vector(doc, "dh.joint_sign", src, 6))
        if any(v not in (1.0, -1.0) for v in sign):
            raise ThermalModelFileError(src, "dh.joint_sign", f"entries must be +1 or -1: {sign}")
        table = replace(table, joint_sign=sign)
    names = tuple(str(n) for n in _get(doc, "sensors.names", src))
    try:
        spec = ThermalSpec.mapped(
            names,
            tuple(_vector(doc, "sensors.reference_degC", src, len(names))),
            tuple(str(n) for n in _get(doc, "sensors.link_sensors", src)),
            offsets=bool(_get(doc, "terms.offsets", src)),
        )
    except ThermalError as exc:
        raise ThermalModelFileError(src, "sensors", str(exc)) from None
    coefficients, std = {}, {}
    for name, entry in dict(_get(doc, "coefficients", src)).items():
        try:
            term_kind_and_link(name)
            coefficients[name] = float(entry["value"])
            std[name] = math.nan if entry.get("std") is None else float(entry["std"])
        except (ThermalError, TypeError, KeyError, ValueError):
            raise ThermalModelFileError(
                src, f"coefficients.{name}", f"bad entry {entry!r}"
            ) from None
        if not math.isfinite(coefficients[name]):
            raise ThermalModelFileError(src, f"coefficients.{name}", "value must be finite")
    return ThermalModel(
        table=table,
        spec=spec,
        coefficients=coefficients,
        std=std,
        refused={str(k): str(v) for k, v in dict(doc.get("refused", {})).items()},
        robot_model=str(doc.get("robot_model", "")),
        T_cell_base=_pose(doc, "T_cell_base", src),
        T_tool0_tcp=_pose(doc, "T_tool0_tcp", src),
        fit={str(k): float(v) for k, v in dict(doc.get("fit", {})).items() if v is not None},
        covariance=_covariance(doc, tuple(coefficients), src),
    )


def load_model(path: str | Path) -> ThermalModel:
    """Read ``thermal.json``; a missing file, bad JSON or a bad field raises a clear error."""
    p = Path(path)
    if not p.is_file():
        raise ThermalModelFileError(str(path), "file", "no such file")
    try:
        doc = json.loads(p.read_text(encoding="utf-8"))
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise ThermalModelFileError(str(path), "file", f"not valid JSON ({exc})") from None
    return model_from_dict(doc, str(path))
