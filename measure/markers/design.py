"""The physical design of a reference marker, in units of the white dot's diameter ``D``.

Both kinds are a white dot (diameter 1) on a black label; the dot's outline is what is measured.

- ``ring``: a round black label (radius ``label_radius``) with the dot in its middle and a code
  ring of ``bits`` equal sectors between ``ring_inner`` and ``ring_outer``, white where the
  code's bit is 1 (:func:`measure.markers.codes.ring_codes`). Sector ``k`` spans the angles
  ``[k, k + 1) · 360° / bits`` from the marker's ``up`` direction, counter-clockwise seen from
  the front.
- ``apriltag``: a rectangular black label holding the dot and, beside it along ``up``, a white
  square field with an AprilTag 36h11 (8 × 8 cells of ``tag_cell`` including its black border,
  one white cell of quiet zone around it) whose centre is ``tag_offset`` from the dot's centre.
  The tag's top row faces the marker's ``normal × up`` side.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from measure.markers.codes import apriltag_count, ring_codes

KINDS = ("ring", "apriltag")


@dataclass(frozen=True)
class MarkerDesign:
    """A marker kind and its geometry (lengths in dot diameters).

    Attributes:
        kind: ``"ring"`` or ``"apriltag"``.
        bits, min_distance: the ring code (sectors, smallest Hamming distance between codes).
        ring_inner, ring_outer: the code ring's radii.
        label_radius: the ring marker's black label radius.
        tag_cell: the AprilTag's cell side; its black square is 8 cells, its white field 10.
        tag_offset: distance from the dot's centre to the tag's centre (along ``up``).
        label_margin: black label beyond the dot (apriltag kind) and beyond the tag's field.
    """

    kind: str = "ring"
    bits: int = 20
    min_distance: int = 3
    ring_inner: float = 0.8
    ring_outer: float = 1.3
    label_radius: float = 1.5
    tag_cell: float = 0.15
    tag_offset: float = 1.85
    label_margin: float = 0.35

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"marker kind must be one of {KINDS}, got {self.kind!r}")
        if self.kind == "ring" and not (
            0.5 < self.ring_inner < self.ring_outer < self.label_radius
        ):
            raise ValueError("ring marker needs 0.5 < ring_inner < ring_outer < label_radius")
        if (
            self.kind == "apriltag"
            and self.tag_offset - 5 * self.tag_cell < 0.5 + self.label_margin
        ):
            raise ValueError("apriltag marker: the tag's field overlaps the dot's black margin")

    @property
    def field_half(self) -> float:
        """Half side of the tag's white field (5 cells), dot diameters."""
        return 5.0 * self.tag_cell

    def label_box(self) -> tuple[float, float, float, float]:
        """The apriltag kind's black label ``(x_lo, x_hi, y_lo, y_hi)`` in dot diameters (x along
        ``up``, y along ``normal × up``)."""
        half = max(0.5 + self.label_margin, self.field_half + 0.5 * self.label_margin)
        x_hi = self.tag_offset + self.field_half + 0.5 * self.label_margin
        return (-(0.5 + self.label_margin), x_hi, -half, half)

    def outer_radius(self, dot_diameter_m: float) -> float:
        """Radius (m) around the dot's centre that holds the whole printed marker."""
        if self.kind == "ring":
            return self.label_radius * dot_diameter_m
        x_lo, x_hi, y_lo, y_hi = self.label_box()
        return math.hypot(max(-x_lo, x_hi), max(-y_lo, y_hi)) * dot_diameter_m

    def n_codes(self) -> int:
        """How many distinct markers the design can identify."""
        if self.kind == "ring":
            return len(ring_codes(self.bits, self.min_distance))
        return apriltag_count()


RING_DESIGN = MarkerDesign(kind="ring")
APRILTAG_DESIGN = MarkerDesign(kind="apriltag")
#: the design the cell uses (chosen by benchmarks/marker_detection.py, docs/markers.md)
DEFAULT_DESIGN = RING_DESIGN
