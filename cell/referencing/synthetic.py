"""Survey and stop observations with a known truth: the markers where they really are (each
off its nominal by a seeded draw, the part's markers moved with the part's true placement),
scale bars of their true length, and each marker's centre projected through the TRUE head
(its calibration error included) with the detector's centre noise.

This simulates the detector's output, not its images: the centre noise ``sigma_px`` is the
figure the marker benchmark measures on rendered images (docs/referencing.md).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from cell.config import CellConfig
from cell.config.markers import marker_codes, marker_in_cell
from cell.referencing.observations import MarkerView, T_left_right, project
from cell.referencing.visibility import seen_each
from measure import StereoCalibration
from robots.transforms import invert

Array = NDArray[np.float64]


@dataclass(frozen=True)
class MarkerTruth:
    """Markers ``ids`` as they are: nominal and true centres (n, 3) and normals, cell frame;
    ``on_fixture`` (n,); ``bar_lengths_m``: each scale bar's true length."""

    ids: tuple[str, ...]
    nominal: Array
    true: Array
    normals: Array
    on_fixture: NDArray[np.bool_]
    bar_lengths_m: tuple[float, ...]
    diameters_m: tuple[float, ...] = ()
    codes: tuple[int, ...] = ()


def draw_marker_truth(
    cell: CellConfig,
    seed: int,
    position_sigma_m: float = 3e-4,
    T_fixture_part: Array | None = None,
    errors: dict[str, tuple[float, float, float]] | None = None,
) -> MarkerTruth:
    """Each marker off its nominal by N(0, ``position_sigma_m``) per axis, or by its offset in
    ``errors`` (m; part frame for a marker on the part, else cell frame); the part's markers
    also moved by the part's placement ``T_fixture_part`` (part frame, identity: none); each
    scale bar's true length off its calibrated ``length_m`` by N(0, U/2), its ``to`` marker
    placed at that distance from its ``from`` marker (the bar carries both)."""
    rng = np.random.default_rng([seed, 0x3A4C])
    T_cell_part = cell.T_cell_part()
    T_place = np.eye(4) if T_fixture_part is None else np.asarray(T_fixture_part, float)
    nominal, true, normals, fixture = [], [], [], []
    for m in cell.reference_markers:
        p, n = marker_in_cell(m, T_cell_part)
        e = rng.normal(0.0, position_sigma_m, 3)
        if errors and m.id in errors:
            e = np.asarray(errors[m.id], float)
        if m.on == "part":
            q = np.asarray(m.position, float) + e
            T = T_cell_part @ T_place
            t_p, t_n = T[:3, :3] @ q + T[:3, 3], T[:3, :3] @ np.asarray(m.normal, float)
        else:
            t_p, t_n = p + e, n
        nominal.append(p)
        true.append(t_p)
        normals.append(t_n)
        fixture.append(m.on == "fixture")
    ids = tuple(m.id for m in cell.reference_markers)
    true_arr = np.array(true)
    bars = []
    for b in cell.scale_bars:  # a bar's end markers are its own: the bar's true length apart
        i, j = ids.index(b.from_), ids.index(b.to)
        length = b.length_m + rng.normal(0.0, b.U_m / 2.0)
        d = true_arr[j] - true_arr[i]
        true_arr[j] = true_arr[i] + d / np.linalg.norm(d) * length
        bars.append(length)
    codes = {mid: code for code, mid in marker_codes(cell.reference_markers).items()}
    return MarkerTruth(
        ids, np.array(nominal), true_arr, np.array(normals), np.array(fixture), tuple(bars),
        tuple(float(m.diameter_m) for m in cell.reference_markers), tuple(codes[i] for i in ids),
    )  # fmt: skip


def observe(
    truth: MarkerTruth,
    true_head: StereoCalibration,
    T_cell_left_true: Array,
    view_id: str,
    sigma_px: float,
    rng: np.random.Generator,
    T_cell_left_prior: Array | None = None,
) -> MarkerView:
    """What the head at its true pose ``T_cell_left_true`` detects: in each camera, every marker
    it sees, the true centre projected through the true head plus N(0, ``sigma_px``) per axis."""
    masks = seen_each(true_head, T_cell_left_true, truth.true, truth.normals)
    out = []
    cams = (T_cell_left_true, T_cell_left_true @ T_left_right(true_head))
    for T_cell_cam, side, mask in zip(cams, ("left", "right"), masks, strict=True):
        ids = [m for m, ok in zip(truth.ids, mask, strict=True) if ok]
        pts = truth.true[mask]
        uv = project(true_head, side, invert(T_cell_cam), pts) if len(pts) else np.zeros((0, 2))
        uv = uv + rng.normal(0.0, sigma_px, uv.shape)
        out.append(dict(zip(ids, uv, strict=True)))
    prior = T_cell_left_true if T_cell_left_prior is None else T_cell_left_prior
    return MarkerView(view_id, out[0], out[1], np.asarray(prior, float))
