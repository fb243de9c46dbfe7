"""The surveyed marker network as a run uses it: ``markers.json`` read and checked, with what
the detector and the resection need of each marker (its code, nominal normal and dot radius).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from cell.config import CellConfig
from cell.config.markers import marker_codes, marker_in_cell
from cell.referencing.errors import MarkersFileError
from cell.referencing.markersfile import MAX_AGE_DAYS, check_markers, load_markers
from measure import StereoCalibration

Array = NDArray[np.float64]

#: the marker centres' standard deviation per image axis assumed by the resection (px): the
#: detector's figure on rendered images (docs/markers.md)
DEFAULT_SIGMA_PX = 0.05


@dataclass(frozen=True, eq=False)
class MarkerNetwork:
    """Surveyed markers ``ids``: ``positions_cell`` (n, 3) m, ``covariance`` (3n, 3n) m²,
    nominal unit ``normals_cell`` (n, 3), dot ``radii_m`` (n,), ``codes`` (code -> id);
    ``head``: the stereo head as the survey self-calibrated it (every referenced stop measures
    with it); ``source``: the file and its date."""

    ids: tuple[str, ...]
    positions_cell: Array
    covariance: Array
    normals_cell: Array
    radii_m: Array
    codes: dict[int, str]
    head: StereoCalibration
    source: str
    sigma_px: float = DEFAULT_SIGMA_PX
    #: the centre noise the resection's covariance is stated at (px): the survey's a posteriori
    #: figure, not below the floor (:mod:`cell.referencing.sigma`); the stated ``sigma_px``
    #: still weighs the observations and sets the outlier limit
    image_sigma_px: float = DEFAULT_SIGMA_PX

    def index(self, marker_id: str) -> int:
        return self.ids.index(marker_id)

    @cached_property
    def geometry(self) -> dict[str, tuple[Array, Array, float]]:
        """Each marker's centre (3,) and unit normal (3,) in the cell frame and its dot's
        radius (m), by id (:data:`cell.referencing.detection.MarkerGeometry`)."""
        return {m: (self.positions_cell[k], self.normals_cell[k], float(self.radii_m[k]))
                for k, m in enumerate(self.ids)}  # fmt: skip

    @cached_property
    def covariance_root(self) -> Array:
        """``L`` (3n, 3n) m with ``L L^T = covariance``: the network's error is ``L z``,
        ``z ~ N(0, I)`` (symmetric eigen-decomposition; negative rounding clipped)."""
        C = np.asarray(self.covariance, float)
        w, v = np.linalg.eigh(0.5 * (C + C.T))
        return v * np.sqrt(np.clip(w, 0.0, None))


def load_network(
    path: str | Path,
    cell: CellConfig,
    stereo: StereoCalibration,
    max_age_days: float | None = MAX_AGE_DAYS,
) -> MarkerNetwork:
    """``markers.json`` of ``cell`` surveyed with ``stereo`` (refused, one line naming the
    field, when it belongs to another cell, marker layout or head, or is too old; any age
    with ``max_age_days`` None)."""
    src = str(path)
    doc, ids, P, C = load_markers(path)
    check_markers(doc, src, cell, stereo, max_age_days)
    try:
        head = StereoCalibration.from_dict(doc["head"], f"{src} (head)")
    except (KeyError, TypeError, ValueError) as exc:
        raise MarkersFileError(src, "head", f"malformed ({exc})") from None
    by_id = {m.id: m for m in cell.reference_markers}
    T_cell_part = cell.T_cell_part()
    normals = np.array([marker_in_cell(by_id[m], T_cell_part)[1] for m in ids])
    radii = np.array([0.5 * by_id[m].diameter_m for m in ids])
    codes = {c: m for c, m in marker_codes(cell.reference_markers).items() if m in set(ids)}
    figures = doc.get("figures") if isinstance(doc.get("figures"), dict) else {}
    stated = _positive(figures.get("sigma_px"), DEFAULT_SIGMA_PX, src, "figures.sigma_px")
    image = _positive(figures.get("sigma_effective_px"), stated, src, "figures.sigma_effective_px")
    return MarkerNetwork(ids, P, C, normals, radii, codes, head,
                         f"{src} ({doc.get('created_utc')})", stated, image)  # fmt: skip


def _positive(value: object, default: float, src: str, field: str) -> float:
    """``value`` as a positive number (``default`` when absent: a file written before it)."""
    if value is None:
        return default
    if isinstance(value, bool) or not isinstance(value, int | float) or not value > 0:
        raise MarkersFileError(src, field, f"must be a positive number of pixels, got {value!r}")
    return float(value)
