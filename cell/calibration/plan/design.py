"""The information-based design of the calibration views and their predicted σ.

Every candidate view's Fisher information comes from the cell calibration's own observation
model and Jacobian (:func:`cell.calibration.estimate.model.predict`, at the nominal cell: the
hand-eye ``T_tool0_camera = T_tool0_tcp @ T_tcp_left``, the target in the base from the cell file,
the stereo extrinsics from the stereo calibration, zero D-H errors): ``I_v = J_v^T J_v / σ_px²``
over the unknowns the adjustment can estimate (the structurally redundant D-H terms are left out, as
the adjustment fixes them). ``σ_px`` (``corner_sigma_px``) is the corner noise per image axis;
the arm's repeatability adds, per view, a rigid displacement of the head of ``σ_rep`` per axis
(``repeatability_sigma_m``, the cell's ISO 9283 RP as :mod:`cell.uncertainty.repeatability`
converts it: 11 µm for the IRB 2600, a fifth of a pixel at 0.25 m), common to all the view's
corners: with ``J_t`` the corners' motion per head displacement (the hand-eye translation
columns) a view's corner covariance is ``Σ_v = σ_px² I + σ_rep² J_t J_t^T`` and its information
``J_v^T Σ_v^-1 J_v`` (by Woodbury's identity).

**Criterion "tcp"** (the default, I-optimal): the calibration matters through the holes it
places. At each of the hole tour's stops ``s`` the point the head measures, the view point
``standoff_m`` ahead of the TCP, moves by ``H_s @ dθ`` (m) for a change ``dθ`` of the unknowns
(hand-eye and D-H terms; the target pose and the stereo extrinsics do not move it), so the
design minimises ``trace(W M^-1)``, ``W = sum_s H_s^T H_s``: the summed variance of the view
points over the stops. **Criterion "d"**: maximises ``log det M`` over every unknown, the target
pose (a nuisance for the run) included. Both add a weak prior (:data:`PRIOR_SIGMA`, about ten
times the realistic errors of a cell) that keeps the first, still singular, greedy steps
comparable; the predicted σ are without it.

**Predicted σ**: for the chosen views, which unknowns the adjustment would estimate
(:func:`cell.calibration.estimate.identifiability.choose_free` on their Jacobian, the
adjustment's own rule) and the covariance of its estimate: the adjustment whitens each view's
residuals by its flange scatter (generalised least squares, ``cell.calibration.estimate.solve``), so
``(sum_v J_v^T Σ_v^-1 J_v)^-1`` over the free unknowns (``σ_px² (J_f^T J_f)^-1`` without
repeatability); from it the σ of the hand-eye, and of the
TCP and the view point at the hole tour's stops (RMS over the stops of ``sqrt(trace(H Σ H^T))``).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from cell.calibration.errors import DegenerateCalibrationError
from cell.calibration.estimate.identifiability import choose_free
from cell.calibration.estimate.model import State, column_names, predict
from cell.calibration.estimate.observations import CalibrationObservations, CalibrationView, Cameras
from cell.calibration.estimate.solve import SolveOptions
from cell.calibration.plan.head_model import stereo_model
from cell.calibration.plan.target import TargetGeometry
from cell.config import CellConfig
from cell.errors import CellError
from measure import StereoCalibration
from measure.target import TargetSpec
from planner.calibration import Candidates, choose_by_information, design_value
from robots.calibration import dh_error_twists, fk_with_errors, structural_redundancies
from robots.design import information_factors
from robots.dh import DHTable
from robots.transforms import invert, skew

Array = NDArray[np.float64]

#: prior σ of the design (poses: m, rad; D-H terms by their unit), about ten times a cell's
#: realistic errors (issue 18: head 1 mm / 0.3 deg, base 1 mm, D-H 0.5 mm / 0.03 deg)
PRIOR_SIGMA = {"pose_m": 0.01, "pose_rad": np.radians(3.0), "dh_m": 0.005, "dh_rad": 0.005}
#: corner noise per image axis assumed for the design and the prediction (px)
CORNER_SIGMA_PX = 0.1


#: candidates whose Jacobian is computed at once (bounds the memory: ~60 kB per view)
CHUNK = 200


@dataclass(frozen=True, eq=False)
class InformationModel:
    """The candidates' information and the stops' sensitivities over ``columns``.

    ``blocks`` (m, p, p): each candidate's information ``J_v^T Σ_v^-1 J_v``; ``jacobians(rows)``
    the row blocks ``J_v`` (px per unit) of those candidates, recomputed by the adjustment's
    model; ``H_view`` / ``H_tcp`` (S, 3, p): the view point's and the TCP's motion per unit of
    each unknown at the stops; ``fixed``: the structurally redundant terms left out, with the
    reason; ``residual_px``: the largest difference between the adjustment's predicted corners
    and the candidates' (0 up to rounding: one lens model).
    """

    columns: tuple[str, ...]
    blocks: Array
    jacobians: Callable[[Sequence[int]], list[Array]]
    H_view: Array
    H_tcp: Array
    fixed: dict[str, str]
    prior: Array
    sigma_px: float
    repeatability_sigma_m: float
    residual_px: float

    @property
    def shift_columns(self) -> list[int]:
        """The hand-eye translation columns: the corners' motion per rigid head displacement."""
        return [self.columns.index(f"T_tool0_camera.{a}_m") for a in "xyz"]


def _dh(cell: CellConfig) -> DHTable:
    dh = cell.build_robot().dh
    if dh is None:
        raise CellError(
            f"robot {cell.robot.model!r}: no D-H table, so the kinematic terms of the "
            "calibration cannot be designed for; use --criterion geometric"
        )
    return dh


def _state(cell: CellConfig, target: TargetGeometry, cameras: Cameras, T_tcp_left: Array) -> State:
    return State(
        T_tool0_camera=cell.T_tool0_tcp() @ T_tcp_left,
        T_base_target=invert(cell.T_cell_base()) @ np.asarray(target.T_cell_target, float),
        T_left_right=cameras.T_left_right,
        delta=np.zeros(24),
    )


def point_sensitivity(dh: DHTable, state: State, q: Array, x_left: Array) -> Array:
    """(S, 3, p): the motion (m per unit) in ``base_link`` of the point ``x_left`` (left camera
    frame, m) fixed to the head at joints ``q`` (S, 6), per unknown of
    ``cell.calibration.estimate.model.column_names(True, True)``."""
    columns = column_names(True, True)
    T_bt = fk_with_errors(dh, state.delta, q)  # (S, 4, 4)
    R_X, t_X = state.T_tool0_camera[:3, :3], state.T_tool0_camera[:3, 3]
    r = R_X @ x_left  # the point relative to the camera origin, in tool0
    P_b = np.einsum("sij,j->si", T_bt[:, :3, :3], r + t_X) + T_bt[:, :3, 3]
    H = np.zeros((len(q), 3, len(columns)))
    H[:, :, 0:3] = T_bt[:, :3, :3]  # hand-eye translation, in tool0
    H[:, :, 3:6] = -T_bt[:, :3, :3] @ skew(r)  # hand-eye rotation vector, in tool0
    tw = dh_error_twists(dh, state.delta, q)  # (S, 24, 6)
    moved = tw[:, :, :3] + np.cross(tw[:, :, 3:], P_b[:, None, :])  # (S, 24, 3)
    k0 = columns.index("dh.a1_m")
    H[:, :, k0 : k0 + 24] = np.transpose(moved, (0, 2, 1))
    return H


def _prior(columns: tuple[str, ...]) -> Array:
    s = [
        PRIOR_SIGMA["dh_m" if c.endswith("_m") else "dh_rad"]
        if c.startswith("dh.")
        else PRIOR_SIGMA["pose_m" if c.endswith("_m") else "pose_rad"]
        for c in columns
    ]
    return np.diag(1.0 / np.square(s))


def _gls_block(Jv: Array, Jt: Array, sigma_px: float, sigma_rep_m: float) -> Array:
    """``J_v^T Σ_v^-1 J_v`` with ``Σ_v = σ_px² I + σ_rep² J_t J_t^T`` (Woodbury's identity)."""
    G = Jv.T @ Jv
    if sigma_rep_m <= 0:
        return G / sigma_px**2
    B = Jt.T @ Jv
    C = Jt.T @ Jt
    k = (sigma_px / sigma_rep_m) ** 2
    return (G - B.T @ np.linalg.solve(k * np.eye(3) + C, B)) / sigma_px**2


def _jacobians(
    dh: DHTable,
    state: State,
    spec: TargetSpec,
    cameras: Cameras,
    cands: Candidates,
    keep: list[int],
    rows: Sequence[int],
) -> tuple[list[Array], float]:
    """The Jacobian row block (px per unit, columns ``keep``) of each candidate of ``rows`` by
    :func:`cell.calibration.estimate.model.predict`, and its largest residual (px)."""
    views = tuple(
        CalibrationView(f"candidate {k}", cands.uv_left[k], cands.uv_right[k], q_rad=cands.q[k])
        for k in rows
    )
    obs = CalibrationObservations(views, spec, cameras, source="calibration plan")
    pred = predict(obs, dh, state, jac=True)
    J = pred.jacobian[:, keep]
    view_of_row = np.repeat(pred.view_index, 2)
    order = np.argsort(view_of_row, kind="stable")
    bounds = np.searchsorted(view_of_row[order], np.arange(len(views) + 1))
    blocks = [J[order[bounds[v] : bounds[v + 1]]] for v in range(len(views))]
    return blocks, float(np.abs(pred.residuals).max())


def information_model(
    cell: CellConfig,
    target: TargetGeometry,
    stereo: StereoCalibration,
    cands: Candidates,
    stops_q: Array,
    sigma_px: float = CORNER_SIGMA_PX,
    repeatability_sigma_m: float = 0.0,
) -> InformationModel:
    """The information of every candidate and the stops' sensitivities (module docstring);
    ``sigma_px`` the corner noise per image axis (px), ``repeatability_sigma_m`` the head's
    rigid scatter per axis and view (m)."""
    dh = _dh(cell)
    cameras = Cameras.from_stereo(stereo)
    T_tcp_left = stereo_model(stereo).T_tcp_left
    state = _state(cell, target, cameras, T_tcp_left)
    spec = target.spec()
    all_cols = column_names(True, True)
    fixed = {f"dh.{k}": v for k, v in structural_redundancies(dh).items()}
    keep = [i for i, c in enumerate(all_cols) if c not in fixed]
    columns = tuple(all_cols[i] for i in keep)
    he = [columns.index(f"T_tool0_camera.{a}_m") for a in "xyz"]
    blocks, residual = [], 0.0
    for lo in range(0, len(cands), CHUNK):
        rows = range(lo, min(lo + CHUNK, len(cands)))
        Js, res = _jacobians(dh, state, spec, cameras, cands, keep, rows)
        residual = max(residual, res)
        blocks += [_gls_block(Jv, Jv[:, he], sigma_px, repeatability_sigma_m) for Jv in Js]
    standoff = np.array([0.0, 0.0, cell.tool.standoff_m, 1.0])
    x_view = (invert(T_tcp_left) @ standoff)[:3]
    x_tcp = invert(T_tcp_left)[:3, 3]
    q = np.atleast_2d(np.asarray(stops_q, dtype=float))
    return InformationModel(
        columns=columns,
        blocks=np.array(blocks),
        jacobians=lambda rows: _jacobians(dh, state, spec, cameras, cands, keep, rows)[0],
        H_view=point_sensitivity(dh, state, q, x_view)[:, :, keep],
        H_tcp=point_sensitivity(dh, state, q, x_tcp)[:, :, keep],
        fixed=fixed,
        prior=_prior(columns),
        sigma_px=sigma_px,
        repeatability_sigma_m=repeatability_sigma_m,
        residual_px=residual,
    )


def _weight(model: InformationModel) -> Array:
    return np.einsum("sia,sib->ab", model.H_view, model.H_view)


#: exchange passes of the information design (greedy alone is within 3 % of ten passes' value
#: on the built-in cell, three within 0.1 %)
EXCHANGE_PASSES = 3


def design_rows(
    model: InformationModel, n: int, criterion: str, starts: list[list[int]]
) -> list[int]:
    """``n`` candidates by ``criterion`` (``"tcp"`` or ``"d"``): greedy and exchange
    (:func:`planner.calibration.choose_by_information`), and exchange from each of ``starts``;
    the best design wins."""
    W = _weight(model) if criterion == "tcp" else None
    U = information_factors(model.blocks)
    passes = EXCHANGE_PASSES
    designs = [choose_by_information(model.blocks, n, model.prior, W, passes, factors=U)]
    for start in starts:
        designs.append(
            choose_by_information(model.blocks, n, model.prior, W, passes, start, factors=U)
        )
    return min(designs, key=lambda r: design_value(model.blocks, r, model.prior, W))


def _rms_point_sigma(H: Array, cov: Array) -> float:
    var = np.einsum("sia,ab,sib->s", H, cov, H)
    return float(np.sqrt(np.mean(var)))


def predict_sigmas(model: InformationModel, rows: list[int]) -> dict[str, Any]:
    """The predicted σ of the calibration from the views ``rows`` (module docstring): what
    ``caltour.json`` stores as ``calibration.prediction``."""
    J = np.vstack(model.jacobians(rows))
    o = SolveOptions()
    try:
        report = choose_free(J, model.columns, {}, o.max_condition, o.effect_floor_px)
    except DegenerateCalibrationError as exc:
        raise CellError(f"the chosen calibration views are degenerate: {exc}") from exc
    idx = [model.columns.index(c) for c in report.free]
    info = model.blocks[list(rows)].sum(axis=0)[np.ix_(idx, idx)]
    norms = np.sqrt(np.diag(info))  # columns scaled to one before inverting (m against rad)
    cov_f = np.linalg.inv(info / np.outer(norms, norms)) / np.outer(norms, norms)
    cov = np.zeros((len(model.columns),) * 2)
    cov[np.ix_(idx, idx)] = cov_f
    sigma = {c: float(np.sqrt(cov_f[i, i])) for i, c in enumerate(report.free)}
    he = [f"T_tool0_camera.{a}" for a in ("x_m", "y_m", "z_m", "rx_rad", "ry_rad", "rz_rad")]
    return {
        "corner_sigma_px": model.sigma_px,
        "repeatability_sigma_m": model.repeatability_sigma_m,
        "sigma": sigma,
        "fixed": {**model.fixed, **report.fixed},
        "condition": report.condition_free,
        "hand_eye_sigma_m": float(np.sqrt(sum(sigma[c] ** 2 for c in he[:3]))),
        "hand_eye_sigma_rad": float(np.sqrt(sum(sigma[c] ** 2 for c in he[3:]))),
        "tcp_sigma_m": _rms_point_sigma(model.H_tcp, cov),
        "view_point_sigma_m": _rms_point_sigma(model.H_view, cov),
        "stops": len(model.H_view),
    }
