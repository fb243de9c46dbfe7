"""A stop located against the surveyed markers (photogrammetric referencing, docs/referencing.md).

At a referenced stop the markers are detected in both images of the hole's pair and the head's
pose in the cell is solved by stereo resection (:func:`cell.referencing.resect`) about the arm's
prior (its kinematics, calibration and thermal model). The hole is then carried into the cell by
the resected pose, not by the arm. The arm's prior removes the markers' perspective bias and
starts the resection; once registered to the markers' frame (:class:`ArmRegistration`) it is
compared with the resection: a difference over :data:`ARM_DISAGREEMENT_M` is flagged (a bumped
fixture, a moved marker group, a wrong calibration). The markers are identified by their codes,
not by the prior. With fewer than four usable markers the stop is
not referenced and the run uses the arm, as without referencing, with its own (larger) budget.

Budget of a referenced stop (part frame, m²): the circle fit, the head's calibration through the
hole and the markers of the same pair (the resected frame moves with the hole: most of it
cancels, :mod:`cell.referencing.head_term`), the resection's image noise, the survey's marker
covariance carried through the resection, the part's temperature.
The arm's repeatability, kinematic calibration and thermal model are not in it: the arm only
carried the head.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from cell.referencing.detection import Detections, observe_detections
from cell.referencing.head_term import referenced_head_covariance, used_view
from cell.referencing.network import MarkerNetwork
from cell.referencing.observations import MarkerView
from cell.referencing.resection import Resection, resect, resect_near
from cell.uncertainty.budget import Contribution
from measure import StereoCalibration
from measure.calibration_uncertainty import CalibrationUncertainty
from robots.transforms import kabsch

Array = NDArray[np.float64]

#: the resected head and the arm's idea of it may differ by this much before it is flagged (m)
ARM_DISAGREEMENT_M = 1e-3
#: referenced stops needed before the arm is registered to the markers' frame
MIN_REGISTRATION_STOPS = 3


class ArmRegistration:
    """The rigid motion from the arm's cell frame to the markers' (the survey's gauge), fitted
    to every referenced stop so far.

    The two frames differ by a rigid motion of the order of a millimetre: the arm's is its
    calibration's (the plate's nominal pose), the markers' is the survey's gauge (the fixture
    markers' nominal places). A stop is judged by how far its resected pose lies from the arm's
    once registered: a jump is a bumped fixture, a moved marker group or a wrong kinematic
    chain, not the frames' offset. Each pose is represented by three points: the camera's
    centre, a point 0.25 m down its view axis and one 0.1 m along its x axis.
    """

    def __init__(self) -> None:
        self.arm: list[Array] = []
        self.markers: list[Array] = []

    @staticmethod
    def _points(T: Array) -> Array:
        o = T[:3, 3]
        return np.array([o, o + 0.25 * T[:3, 2], o + 0.1 * T[:3, 0]])

    def add(self, T_cell_left_arm: Array, T_cell_left_markers: Array) -> None:
        self.arm.append(self._points(T_cell_left_arm))
        self.markers.append(self._points(T_cell_left_markers))

    def transform(self) -> Array | None:
        """The rigid motion (4, 4) taking the arm's cell frame into the markers' (None before
        :data:`MIN_REGISTRATION_STOPS`): a stop that falls back to the arm is carried through
        it, so that its hole is in the same frame as the referenced ones."""
        if len(self.arm) < MIN_REGISTRATION_STOPS:
            return None
        R, t, _ = kabsch(np.vstack(self.arm), np.vstack(self.markers)[None])
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = R[0], t[0]
        return T

    def place(self, located: LocatedStop) -> LocatedStop:
        """``located`` with what the stops before say of it: a stop that fell back carries the
        registered arm's pose; a referenced one its distance from it (``registered_m``), and it
        joins the fit unless that flags it (a stop off the others does not move the fit)."""
        T_arm = located.T_cell_left_arm
        if not located.referenced:
            T_reg = self.transform()
            if T_reg is None:
                return located
            return replace(located, T_cell_left_registered=T_reg @ T_arm)
        T_res = located.resection.T_cell_left
        located = replace(located, registered_m=self.residual_m(T_arm, T_res))
        if not located.flagged:
            self.add(T_arm, T_res)
        return located

    def residual_m(self, T_cell_left_arm: Array, T_cell_left_markers: Array) -> float:
        """Largest distance (m) of the stop's points after registering the arm to the markers
        on the stops so far (NaN before :data:`MIN_REGISTRATION_STOPS`)."""
        if len(self.arm) < MIN_REGISTRATION_STOPS:
            return math.nan
        R, t, _ = kabsch(np.vstack(self.arm), np.vstack(self.markers)[None])
        P = self._points(T_cell_left_arm) @ R[0].T + t[0]
        return float(np.linalg.norm(P - self._points(T_cell_left_markers), axis=1).max())


@dataclass(frozen=True)
class HeadInputs:
    """What the head's calibration row of a referenced stop needs: the head the hole was
    measured with, its uncertainty and the hole's inlier edge points (left frame, m)."""

    stereo: StereoCalibration
    uncertainty: CalibrationUncertainty
    points_left_m: Array


@dataclass(frozen=True, eq=False)
class LocatedStop:
    """A stop's resection (``resection.ok`` False: not referenced, ``resection.reason`` why),
    the markers seen (``view``), how far the arm's prior was from it (m, rad), and how far once
    the arm is registered to the markers' frame (``registered_m``, :class:`ArmRegistration`;
    NaN before enough stops)."""

    resection: Resection
    view: MarkerView
    T_cell_left_arm: Array
    disagreement_m: float
    disagreement_rad: float
    registered_m: float = math.nan
    #: d (w, tau) / d z (6, 3n): the stop's pose error for the network's error ``L z``
    #: (:attr:`MarkerNetwork.covariance_root`); None without a network covariance
    marker_factor: Array | None = None
    #: a stop that fell back: the arm's pose carried into the markers' frame (None: too few
    #: referenced stops before it to register the arm; the arm's own frame is used)
    T_cell_left_registered: Array | None = None
    #: the network the stop was resected against: ids and positions (n, 3) m, cell frame (for
    #: the head's calibration row, :func:`cell.referencing.head_term.referenced_head_covariance`)
    marker_ids: tuple[str, ...] = ()
    marker_positions: Array | None = None
    #: the CPU time :func:`locate_stop` took (s): both passes of the bias and the resection
    cpu_s: float = math.nan

    @property
    def referenced(self) -> bool:
        return bool(self.resection.ok)

    @property
    def flagged(self) -> bool:
        """The resection and the registered arm disagree by more than
        :data:`ARM_DISAGREEMENT_M`."""
        return self.referenced and self.registered_m > ARM_DISAGREEMENT_M

    def to_dict(self) -> dict[str, Any]:
        """What a hole result stores of it (``extra["referencing"]``)."""
        r = self.resection
        out: dict[str, Any] = {
            "referenced": self.referenced,
            "markers": list(r.used),
            "refused": dict(r.refused),
            "seen_left": sorted(self.view.uv_left),
            "seen_right": sorted(self.view.uv_right),
        }
        if self.referenced:
            out |= {"rms_px": r.rms_px, "arm_disagreement_m": self.disagreement_m,
                    "arm_disagreement_rad": self.disagreement_rad,
                    "arm_registered_m": None if math.isnan(self.registered_m)
                    else self.registered_m,
                    "T_cell_left": r.T_cell_left.tolist(),
                    "T_cell_left_arm": self.T_cell_left_arm.tolist()}  # fmt: skip
        else:
            out["reason"] = r.reason
            out["registered_arm"] = self.T_cell_left_registered is not None
        return out


def locate_stop(
    network: MarkerNetwork,
    detections: Detections,
    T_cell_left_arm: Array,
    view_id: str,
) -> LocatedStop:
    """Resect the head against the surveyed markers detected in the pair
    (:func:`cell.referencing.detection.detect_pair`), about the arm's pose; then once more with
    the markers' perspective bias removed at the resected pose (one Gauss-Newton step from it,
    :func:`cell.referencing.resection.resect_near`), so that the result does not
    depend on the arm's prior (a prior 1.7 mm and 0.09 deg off moved the bias by up to 0.0013 px
    and the hole by up to 0.18 um; the arm's frame and the markers' differ by about 1 mm)."""
    cpu0 = time.thread_time()
    args = (network.head, network.ids, network.positions_cell)
    noise = (network.sigma_px, network.image_sigma_px)
    view = observe_detections(detections, network.head, network.codes, network.geometry,
                              view_id, T_cell_left_arm)  # fmt: skip
    r = resect(view, *args, None, *noise)  # the pose only: no marker covariance
    if r.ok:
        again = observe_detections(detections, network.head, network.codes, network.geometry,
                                   view_id, r.T_cell_left)  # fmt: skip
        # the first pass's refusals kept; this pass decides (its outlier test included)
        r2 = resect_near(used_view(again, r.used), *args, network.covariance, *noise)
        view, r = again, replace(r2, refused={**r.refused, **r2.refused})
    dt, dr = math.nan, math.nan
    if r.ok:
        D = np.linalg.inv(T_cell_left_arm) @ r.T_cell_left
        dt = float(np.linalg.norm(r.T_cell_left[:3, 3] - T_cell_left_arm[:3, 3]))
        dr = float(np.arccos(np.clip((np.trace(D[:3, :3]) - 1.0) / 2.0, -1.0, 1.0)))
    factor = None
    if r.ok and r.marker_sensitivity is not None:
        cols = np.asarray(r.marker_columns, np.int64)
        rows = (3 * cols[:, None] + np.arange(3)).ravel()
        factor = r.marker_sensitivity @ network.covariance_root[rows]
    return LocatedStop(
        r,
        view,
        np.asarray(T_cell_left_arm, float),
        dt,
        dr,
        marker_factor=factor,
        marker_ids=network.ids,
        marker_positions=network.positions_cell,
        cpu_s=time.thread_time() - cpu0,
    )


def survey_markers_factor(
    located: LocatedStop, center_left_m: Array, R_part_cell: Array
) -> Array | None:
    """The hole centre's error in the part frame for the network's error ``L z`` (3, 3n) m:
    the stops that share markers share it (:mod:`cell.gdt.montecarlo`); None when the stop is
    not referenced or the network has no covariance."""
    if not located.referenced or located.marker_factor is None:
        return None
    J = R_part_cell @ located.resection.point_jacobian(center_left_m)
    return J @ located.marker_factor


def referenced_contributions(
    located: LocatedStop,
    center_left_m: Array,
    R_part_cell: Array,
    fit: Contribution,
    calibration: Contribution,
    temperature: Contribution,
    network_source: str,
    head: HeadInputs | None = None,
) -> list[Contribution]:
    """The budget rows of a referenced stop (module doc): the fit and the part temperature as
    given, the resection's image noise and the survey's markers; the head's calibration through
    the hole and the markers of the same pair when ``head`` is given
    (:func:`cell.referencing.head_term.referenced_head_covariance`), else ``calibration`` as
    given (the head's error as if the arm had carried the camera frame: a bound)."""
    r = located.resection
    if head is not None and located.marker_positions is not None:
        cov = referenced_head_covariance(
            head.stereo, head.uncertainty, used_view(located.view, r.used), located.marker_ids,
            located.marker_positions, r.T_cell_left, head.points_left_m,
        )  # fmt: skip
        calibration = Contribution(
            calibration.name, R_part_cell @ cov @ R_part_cell.T, calibration.var_diameter_m2,
            f"{calibration.note}; through the hole and the {len(r.used)} markers of the same pair",
        )  # fmt: skip
    J = R_part_cell @ r.point_jacobian(center_left_m)
    cov_m = r.covariance_markers if r.covariance_markers is not None else np.zeros((6, 6))
    image = Contribution(
        "resection", J @ (r.covariance - cov_m) @ J.T, 0.0,
        f"stereo resection on {len(r.used)} markers ({', '.join(r.used)}), "
        f"{r.rms_px:.3f} px RMS",
    )  # fmt: skip
    survey = Contribution("survey_markers", J @ cov_m @ J.T, 0.0,
                          f"the surveyed markers' covariance ({network_source})")  # fmt: skip
    return [fit, calibration, image, survey, temperature]


def located_note(hole_id: str, located: LocatedStop) -> tuple[str, str] | None:
    """The run-log event of a stop's referencing when there is something to say."""
    r = located.resection
    if not located.referenced:
        return "referencing", (f"{hole_id}: not referenced ({r.reason}): carried into the part by "
                               "the arm, with the arm's budget")  # fmt: skip
    if r.refused:
        refused = "; ".join(f"{m}: {why}" for m, why in r.refused.items())
        return "referencing", f"{hole_id}: marker(s) refused: {refused}"
    if located.flagged:
        return "fault", (f"{hole_id}: the markers place the head {located.registered_m * 1e3:.2f}"
                         " mm from where the arm, registered to them on the stops before, says "
                         f"it is (over {ARM_DISAGREEMENT_M * 1e3:g} mm): a bumped fixture, moved "
                         "markers or a wrong calibration?")  # fmt: skip
    return None
