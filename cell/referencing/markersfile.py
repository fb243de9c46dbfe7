"""``markers.json``: a survey's marker network, the file ``holecell run --markers`` reads.

Layout (SI units, cell frame)::

    {"format": "holecell.markers", "version": 1, "created_utc": "2026-12-04T05:00:00Z",
     "provenance": {"cell": "<name>", "cell_fingerprint": "...", "stereo_source": "...",
                    "stereo_fingerprint": "..."},
     "gauge": "fixture markers", "scale": {"sigma_ppm": 0.6, "source": "2 scale bars ..."},
     "figures": {"rms_px": 0.05, "variance_factor": 1.0, "views": 540, "observations": 13776},
     "markers": [{"id": "P001", "position_m": [x, y, z]}, ...],
     "covariance_m2": [[...3n...], ...], "warnings": [...]}

The cell fingerprint covers the cell's name, the part's placement and every marker's id, side
(``on``) and nominal position: a run refuses a file of another cell or another marker layout,
or of another stereo head, and one older than its age limit.
"""

from __future__ import annotations

import json
import math
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np

from cell.calibration.file import fingerprint
from cell.config import CellConfig
from cell.referencing.errors import MarkersFileError
from cell.referencing.survey.result import SurveyResult
from measure import StereoCalibration
from robots.files import write_text_atomic

FORMAT = "holecell.markers"
FORMAT_VERSION = 1
#: a survey older than this is refused by default (days): markers get knocked, fixtures move
MAX_AGE_DAYS = 7.0
#: the copy a referenced run keeps in its run directory
MARKERS_FILENAME = "markers.json"


def cell_fingerprint(cell: CellConfig) -> str:
    """Fingerprint of the cell's marker layout (module doc)."""
    return fingerprint(
        {
            "name": cell.name,
            "part_base": cell.part.base.model_dump(mode="json"),
            "markers": [[m.id, m.on, m.position] for m in cell.reference_markers],
        }
    )


def save_markers(
    path: str | Path,
    result: SurveyResult,
    cell: CellConfig,
    stereo: StereoCalibration,
    created_utc: str | None = None,
) -> Path:
    """Write ``result`` as ``markers.json`` (atomically)."""
    doc: dict[str, Any] = {
        "format": FORMAT,
        "version": FORMAT_VERSION,
        "created_utc": created_utc or datetime.now(UTC).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "provenance": {
            "cell": cell.name,
            "cell_fingerprint": cell_fingerprint(cell),
            "stereo_source": stereo.source,
            "stereo_fingerprint": fingerprint(stereo.to_dict()),
        },
        "head": (result.stereo or stereo).to_dict(),
        "gauge": result.gauge,
        "scale": {"sigma_ppm": result.scale_sigma_ppm, "source": result.scale_source},
        "figures": {
            "rms_px": result.rms_px,
            "variance_factor": result.variance_factor,
            "sigma_px": result.sigma_px,
            "sigma_effective_px": result.sigma_effective_px,
            "sigma_floor_px": result.sigma_floor_px,
            "views": result.n_views,
            "observations": result.n_observations,
        },
        "markers": [
            {"id": m, "position_m": [float(v) for v in p]}
            for m, p in zip(result.marker_ids, result.positions_cell, strict=True)
        ],
        "covariance_m2": [[float(v) for v in row] for row in result.covariance],
        "warnings": list(result.warnings),
    }
    return write_text_atomic(path, json.dumps(doc, indent=1) + "\n")


def load_markers(
    path: str | Path,
) -> tuple[dict[str, Any], tuple[str, ...], np.ndarray, np.ndarray]:
    """``(document, ids, positions (n, 3) m, covariance (3n, 3n) m²)`` of ``markers.json``;
    :class:`MarkersFileError` naming the field when it is malformed."""
    src = str(path)
    try:
        doc = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError) as exc:
        raise MarkersFileError(src, "<file>", f"cannot be read ({exc})") from None
    except json.JSONDecodeError as exc:
        raise MarkersFileError(
            src, "<file>", f"is not JSON ({exc.msg}, line {exc.lineno})"
        ) from None
    if not isinstance(doc, dict) or doc.get("format") != FORMAT:
        found = doc.get("format") if isinstance(doc, dict) else type(doc).__name__
        raise MarkersFileError(src, "format", f"expected {FORMAT!r}, found {found!r}")
    if doc.get("version") != FORMAT_VERSION:
        raise MarkersFileError(
            src, "version", f"this reads version {FORMAT_VERSION}, found {doc.get('version')!r}"
        )
    try:
        ids = tuple(str(m["id"]) for m in doc["markers"])
        P = np.array([m["position_m"] for m in doc["markers"]], dtype=float).reshape(len(ids), 3)
        C = np.array(doc["covariance_m2"], dtype=float).reshape(3 * len(ids), 3 * len(ids))
    except (KeyError, TypeError, ValueError) as exc:
        raise MarkersFileError(src, "markers", f"malformed ({exc})") from None
    if (
        not np.all(np.isfinite(P))
        or not np.all(np.isfinite(C))
        or not np.allclose(C, C.T, atol=1e-18)
    ):
        raise MarkersFileError(src, "covariance_m2", "must be finite and symmetric")
    return doc, ids, P, C


def check_markers(
    doc: dict[str, Any],
    src: str,
    cell: CellConfig,
    stereo: StereoCalibration,
    max_age_days: float | None = MAX_AGE_DAYS,
    now: datetime | None = None,
) -> None:
    """Refuse a ``markers.json`` of another cell or marker layout, another head, or too old
    (``max_age_days`` None: any age, the copy a resumed run stored)."""
    prov = doc.get("provenance") or {}
    if prov.get("cell_fingerprint") != cell_fingerprint(cell):
        raise MarkersFileError(
            src,
            "provenance.cell_fingerprint",
            f"surveyed for another cell or "
            f"marker layout ({prov.get('cell')!r}); survey this cell: holecell survey",
        )
    if prov.get("stereo_fingerprint") != fingerprint(stereo.to_dict()):
        raise MarkersFileError(
            src,
            "provenance.stereo_fingerprint",
            f"surveyed with another stereo calibration ({prov.get('stereo_source')!r})",
        )
    try:
        created = datetime.strptime(str(doc.get("created_utc")), "%Y-%m-%dT%H:%M:%SZ").replace(
            tzinfo=UTC
        )
    except ValueError:
        raise MarkersFileError(
            src, "created_utc", f"must be YYYY-MM-DDTHH:MM:SSZ, got {doc.get('created_utc')!r}"
        ) from None
    age = ((now or datetime.now(UTC)) - created).total_seconds() / 86400.0
    if max_age_days is None:
        return
    if not math.isfinite(max_age_days) or age > max_age_days:
        raise MarkersFileError(
            src,
            "created_utc",
            f"the survey is {age:.1f} days old, the limit is "
            f"{max_age_days:g} days: survey again (--markers-max-age to allow it)",
        )
