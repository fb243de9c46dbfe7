"""The D-H tables (:mod:`robots.dh`) of the built-in arm models (:mod:`robots.models`),
derived from their URDFs (:mod:`robots.arm_kinematics`) and cached per model."""

from __future__ import annotations

from functools import lru_cache

from robots.dh import DHTable
from robots.models import MODELS, ArmSpec


def dh_table(spec: ArmSpec | str) -> DHTable:
    """The D-H table of a built-in model (by spec or name), derived from its URDF.

    Same derivation as for any URDF (:mod:`robots.dh_derive` from the OPW parameters of
    :mod:`robots.opw`), so the table cannot disagree with the URDF.
    """
    return _builtin_table(spec if isinstance(spec, str) else spec.name)


@lru_cache(maxsize=8)
def _builtin_table(name: str) -> DHTable:
    # Pinocchio and the URDF parser: loaded on the first table only
    from robots.arm_kinematics import derive_kinematics
    from robots.urdf_load import load_urdf
    from robots.urdf_writer import URDF_DIR

    if name not in MODELS:
        raise KeyError(name)
    table = derive_kinematics(load_urdf(URDF_DIR / f"{name}.urdf")).dh
    assert table is not None  # the built-in chains have the ABB layout
    return table
