"""Shared fixtures of the thermal tests: an IRB 2600 with a stereo head and a small pose plan."""

from __future__ import annotations

import numpy as np
import pytest

from robots.dh import DHTable, fk_dh
from robots.dh_models import dh_table
from robots.thermal import CellGeometry
from robots.transforms import pose_to_matrix

#: six poses spread over the workspace (rad)
PLAN_Q = (
    (0.0, 0.3, -0.2, 0.5, 0.8, 0.1),
    (0.6, 0.1, 0.2, -0.5, 1.0, 0.3),
    (-0.7, 0.5, -0.4, 0.2, -0.9, -0.2),
    (0.2, -0.2, 0.5, 1.2, 0.5, 0.0),
    (-0.3, 0.8, -0.9, -1.0, 1.2, 0.5),
    (1.0, 0.4, -0.1, 0.0, 0.6, 1.0),
)


@pytest.fixture(scope="session")
def table() -> DHTable:
    return dh_table("abb_irb2600_20_165")


@pytest.fixture(scope="session")
def T_cell_base() -> np.ndarray:
    return pose_to_matrix([0.2, -0.1, 0.05], rpy=[0.0, 0.0, 0.3])


@pytest.fixture(scope="session")
def T_tool0_tcp() -> np.ndarray:
    return pose_to_matrix([0.0, 0.05, 0.35], rpy=[0.0, 0.1, 0.0])


def geometry_for(table: DHTable, T_cell_base: np.ndarray, T_tool0_tcp: np.ndarray, qs) -> tuple:
    """A cell whose target ``R<i>`` sits 2 mm off the nominal TCP of pose ``i``; and the plan."""
    targets = {}
    plan = []
    for i, q in enumerate(qs):
        T_cell_tcp = T_cell_base @ fk_dh(table, np.asarray(q)) @ T_tool0_tcp
        targets[f"R{i}"] = (T_cell_tcp @ np.array([0.002, -0.001, 0.0, 1.0]))[:3]
        plan.append((f"R{i}", np.asarray(q, float)))
    return CellGeometry(T_cell_base, T_tool0_tcp, targets), plan


@pytest.fixture(scope="session")
def cell(table, T_cell_base, T_tool0_tcp):
    return geometry_for(table, T_cell_base, T_tool0_tcp, PLAN_Q)


@pytest.fixture(scope="session")
def make_cell(table, T_cell_base, T_tool0_tcp):
    """``make_cell(qs)`` -> (geometry, plan) for other joint vectors."""
    return lambda qs: geometry_for(table, T_cell_base, T_tool0_tcp, qs)
