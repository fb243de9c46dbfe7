"""Any image a camera can produce gives a result or a clean MeasurementError, never a crash."""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import pytest
from measure_helpers import render, small_stereo

from measure import HoleMeasurement, measure_hole
from measure.errors import MeasurementError
from measure.synth import RenderOptions


@lru_cache(maxsize=1)
def _good():
    return render(0.008, 10.0, 31)


@lru_cache(maxsize=1)
def _images() -> dict[str, np.ndarray]:
    """Pathological single images of the small head's size (640×512) and others."""
    rng = np.random.default_rng(5)
    h, w = 512, 640
    yy, xx = np.mgrid[0:h, 0:w]
    hole = _good().left
    discs = np.full((h, w), 150, np.uint8)
    for _ in range(40):  # many small dark discs: a perforated plate
        cx, cy, r = rng.integers(20, w - 20), rng.integers(20, h - 20), rng.integers(3, 25)
        discs[(xx - cx) ** 2 + (yy - cy) ** 2 < r * r] = 20
    checker = (((xx // 40) + (yy // 40)) % 2 * 200 + 20).astype(np.uint8)
    return {
        "black": np.zeros((h, w), np.uint8),
        "white": np.full((h, w), 255, np.uint8),
        "saturated 16-bit": np.full((h, w), 65535, np.uint16),
        "one gray level": np.full((h, w), 77, np.uint8),
        "noise 8-bit": rng.integers(0, 256, (h, w), dtype=np.uint8),
        "noise 16-bit": rng.integers(0, 65536, (h, w), dtype=np.uint16),
        "noise 12-bit colour": rng.integers(0, 4096, (h, w, 3), dtype=np.uint16),
        "16-bit colour hole": np.dstack([hole.astype(np.uint16) * 257] * 3),
        "8-bit data in uint16": hole.astype(np.uint16),
        "BGRA hole": np.dstack([hole] * 3 + [np.full_like(hole, 255)]),
        "gradient": (xx * 255 // w).astype(np.uint8),
        "one bright pixel": np.pad(np.full((1, 1), 255, np.uint8), ((256, 255), (320, 319))),
        "half saturated": np.where(xx < w // 2, 255, 40).astype(np.uint8),
        "perforated plate": discs,
        "chessboard": checker,
        "hole negative": 255 - hole,
        "hole, 1 DN contrast": (hole // 128).astype(np.uint8),
    }


@pytest.mark.parametrize("name", list(_images()))
def test_every_image_gives_a_result_or_a_measurement_error(name):
    img = _images()[name]
    good = _good()
    other = good.right if img.ndim == 2 else np.dstack([good.right] * img.shape[2])
    other = other.astype(img.dtype) * (257 if img.dtype == np.uint16 and img.max() > 255 else 1)
    for left, right in ((img, img), (img, other), (other, img)):
        try:
            m = measure_hole(left, right, small_stereo())
        except MeasurementError as exc:
            assert "\n" not in str(exc) and len(str(exc)) < 600
        else:
            assert isinstance(m, HoleMeasurement) and np.isfinite(m.radius_m)


@pytest.mark.parametrize(
    "bad",
    [
        np.zeros((0, 0), np.uint8),
        np.zeros((5, 7), np.uint8),
        np.zeros((512, 640), np.int32),
        np.zeros((512, 640), np.float64),
        np.zeros((512, 640), bool),
        np.zeros((512, 640, 2), np.uint8),
        np.zeros(640, np.uint8),
        [[0, 1], [2, 3]],
        None,
    ],
    ids=["empty", "tiny", "int32", "float64", "bool", "two channels", "1-D", "list", "None"],
)
def test_malformed_arrays_are_refused_cleanly(bad):
    with pytest.raises(MeasurementError):
        measure_hole(bad, bad, small_stereo())


def test_realistic_colour_pair_is_measured():
    """A Bayer-demosaiced, JPEG-compressed colour pair with a screw inside the bore."""
    opts = RenderOptions(
        bayer=True, jpeg_quality=90, object_fraction=0.4, wall_light=0.5, light_gradient=0.3
    )
    r = render(0.008, 15.0, 32, opts)
    assert r.left.ndim == 3
    m = measure_hole(r.left, r.right, small_stereo(), expected_standoff_m=0.25)
    assert abs(m.radius_m - r.truth.edge_radius_m) < 5e-6
    assert m.rim is not None and m.rim.polarity == "dark"
    assert m.status == "ok", m.suspect_reasons
