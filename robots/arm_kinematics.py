"""An arm's kinematics from its URDF: OPW parameters and D-H rows, both checked against the URDF.

At load, the URDF's forward kinematics (Pinocchio) and the derived OPW forward kinematics must
agree at :data:`CHECK_CONFIGURATIONS` random configurations within the joint limits to
:data:`CHECK_TOL_M` (position, m, and rotation matrix entries); so must the D-H rows, and so
must a D-H table given by the caller. The D-H rows (used by the thermal model) are derived from
the same joint axis lines as the OPW parameters, so no hand-kept table can disagree.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from robots.dh import DHTable, fk_dh
from robots.dh_derive import dh_from_lines
from robots.errors import DHFormError, NotOpwError, UrdfError
from robots.opw import OpwParameters, derive_opw, fk_opw, joint_lines_of
from robots.urdf_load import LoadedUrdf

Array = NDArray[np.float64]

CHECK_CONFIGURATIONS = 128
CHECK_TOL_M = 1e-9
CHECK_SEED = 20140101


@dataclass(frozen=True)
class ArmKinematics:
    """What the arm's IK and thermal model use, derived from its URDF.

    Attributes:
        opw: the OPW parameters (IK).
        dh: the D-H table (thermal model), or ``None`` when the chain has no D-H form with
            frame 0 = base_link (then ``dh_problem`` says why).
        fk_error_m: largest URDF-vs-OPW difference over the check configurations (m).
    """

    opw: OpwParameters
    dh: DHTable | None
    dh_problem: str | None
    fk_error_m: float


def check_configurations(lower: Array, upper: Array) -> Array:
    """The (N, 6) joint vectors (rad) of the load-time check, within the limits."""
    rng = np.random.default_rng(CHECK_SEED)
    lo = np.maximum(lower, -2 * np.pi)
    hi = np.minimum(upper, 2 * np.pi)
    return rng.uniform(lo, hi, (CHECK_CONFIGURATIONS, 6))


def urdf_fk(loaded: LoadedUrdf, Q: Array) -> Array:
    """``T_base_tool0`` (N, 4, 4) of the URDF (Pinocchio) at joint vectors ``Q`` (N, 6)."""
    model = loaded.model
    data = model.createData()
    fid = model.getFrameId("tool0")
    out = np.empty((len(Q), 4, 4))
    for k, q in enumerate(Q):
        pin.framesForwardKinematics(model, data, q)
        out[k] = data.oMf[fid].homogeneous
    return out


def fk_difference(T_a: Array, T_b: Array) -> tuple[float, int]:
    """Largest position (m) / rotation-entry difference between two pose stacks, and where."""
    err = np.maximum(
        np.linalg.norm(T_a[:, :3, 3] - T_b[:, :3, 3], axis=1),
        np.abs(T_a[:, :3, :3] - T_b[:, :3, :3]).max(axis=(1, 2)),
    )
    k = int(np.argmax(err))
    return float(err[k]), k


def derive_kinematics(loaded: LoadedUrdf) -> ArmKinematics:
    """OPW parameters and D-H rows of a loaded URDF, checked against its forward kinematics."""
    opw = derive_opw(loaded.lines, loaded.T_base_tool0_zero)
    Q = check_configurations(loaded.model.lowerPositionLimit, loaded.model.upperPositionLimit)
    T_urdf = urdf_fk(loaded, Q)
    err, k = fk_difference(T_urdf, fk_opw(opw, Q))
    if err > CHECK_TOL_M:
        raise NotOpwError(
            "(chain)",
            f"the derived OPW kinematics differ from the URDF by {err:.3g} m at "
            f"q = {np.round(Q[k], 4).tolist()} rad",
        )
    try:
        dh = dh_from_lines(joint_lines_of(opw), loaded.T_base_tool0_zero)
    except DHFormError as exc:
        return ArmKinematics(opw, None, str(exc), err)
    dh_err, k = fk_difference(T_urdf, fk_dh(dh, Q))
    if dh_err > CHECK_TOL_M:  # a derivation bug, never a user error: say so loudly
        raise UrdfError(str(loaded.path), f"derived D-H rows differ from it by {dh_err:.3g} m")
    return ArmKinematics(opw, dh, None, err)


def check_given_table(loaded: LoadedUrdf, table: DHTable, lower: Array, upper: Array) -> None:
    """Refuse a caller's D-H table that does not reproduce the URDF (CHECK_TOL_M)."""
    Q = check_configurations(lower, upper)
    err, k = fk_difference(urdf_fk(loaded, Q), fk_dh(table, Q))
    if err > CHECK_TOL_M:
        raise UrdfError(
            str(loaded.path),
            f"the D-H table given does not match the URDF: tool0 {err:.3g} m apart at "
            f"q = {np.round(Q[k], 4).tolist()} rad",
        )
