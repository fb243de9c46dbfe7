"""Exceptions of the ``measure`` package: one base, specific subclasses with payloads.

Every failure a user can cause (bad images, bad calibration, no or several holes, a hole
of the wrong size) raises a subclass of :class:`MeasurementError` whose message names
the file, field or value at fault. The CLI prints the message without a traceback.
"""

from __future__ import annotations


class MeasurementError(Exception):
    """Base of every error raised by :mod:`measure`."""


class CalibrationError(MeasurementError):
    """A stereo calibration is missing, malformed or does not fit the images.

    ``source`` names the file (or ``"<memory>"``), ``field`` the offending field.
    """

    def __init__(self, source: str, field: str, reason: str) -> None:
        self.source = source
        self.field = field
        self.reason = reason
        super().__init__(f"{source}: {field}: {reason}")


class ImageError(MeasurementError):
    """An image cannot be measured: wrong type, size mismatch, saturated or black.

    ``which`` is ``"left"``, ``"right"`` or ``"pair"``.
    """

    def __init__(self, which: str, reason: str) -> None:
        self.which = which
        self.reason = reason
        super().__init__(f"{which} image: {reason}")


class HoleNotFoundError(MeasurementError):
    """No disc-like hole region was found in an image."""

    def __init__(self, which: str, reason: str) -> None:
        self.which = which
        self.reason = reason
        super().__init__(f"{which} image: no hole found: {reason}")


class AmbiguousHoleError(MeasurementError):
    """Several hole-like regions are in view and nothing tells which one to measure.

    ``candidates`` lists ``(x_px, y_px, equivalent diameter_px)`` per region.
    """

    def __init__(self, which: str, candidates: list[tuple[float, float, float]]) -> None:
        self.which = which
        self.candidates = candidates
        where = ", ".join(f"({x:.0f}, {y:.0f}) px ⌀{d:.0f} px" for x, y, d in candidates[:5])
        if len(candidates) > 5:
            where += ", …"
        super().__init__(
            f"{which} image: {len(candidates)} holes in view ({where}); "
            "give the expected diameter or a region of interest"
        )


class HoleAtBorderError(MeasurementError):
    """The hole region touches the image (or region of interest) border."""

    def __init__(self, which: str, bbox: tuple[int, int, int, int]) -> None:
        self.which = which
        self.bbox = bbox
        super().__init__(
            f"{which} image: the hole is cut by the image border (region x, y, w, h = {bbox})"
        )


class HoleSizeError(MeasurementError):
    """The measured hole is far from the expected diameter."""

    def __init__(self, measured_m: float, expected_m: float, tolerance: float) -> None:
        self.measured_m = measured_m
        self.expected_m = expected_m
        self.tolerance = tolerance
        super().__init__(
            f"hole diameter {measured_m * 1e3:.3f} mm is far from the expected "
            f"{expected_m * 1e3:.3f} mm (allowed ±{tolerance * 100:.0f} %)"
        )


class EdgeError(MeasurementError):
    """Too few usable edge points (or stereo matches) to fit a circle."""

    def __init__(self, stage: str, n_points: int, needed: int) -> None:
        self.stage = stage
        self.n_points = n_points
        self.needed = needed
        super().__init__(f"{stage}: only {n_points} usable points, {needed} needed")


class FitError(MeasurementError):
    """The spatial circle fit failed or produced a degenerate circle."""

    def __init__(self, reason: str) -> None:
        self.reason = reason
        super().__init__(f"circle fit failed: {reason}")


class CalibrationTargetError(MeasurementError):
    """``holecell calibrate`` could not use enough image pairs.

    ``rejected`` lists ``(pair name, reason)``.
    """

    def __init__(self, reason: str, rejected: list[tuple[str, str]]) -> None:
        self.reason = reason
        self.rejected = rejected
        lines = [reason] + [f"  {name}: {why}" for name, why in rejected]
        super().__init__("\n".join(lines))


class StereoMismatchError(MeasurementError):
    """Hole candidates were found in both images, but no left/right pair is one hole.

    ``counts`` maps each failed check (``"epipolar"``, ``"size"``, ``"depth"``,
    ``"expected size"``) to the number of candidate pairs it ruled out; ``detail`` names the
    closest pair's figures.
    """

    def __init__(self, n_left: int, n_right: int, counts: dict[str, int], detail: str) -> None:
        self.n_left = n_left
        self.n_right = n_right
        self.counts = counts
        self.detail = detail
        why = ", ".join(f"{n} by {k}" for k, n in counts.items() if n)
        super().__init__(
            f"left and right images do not show the same hole: {n_left} left × {n_right} "
            f"right candidates, every pair ruled out ({why}); {detail}"
        )
