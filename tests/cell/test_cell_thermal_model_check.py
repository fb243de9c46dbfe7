"""A ``--thermal`` model is applied with the cell's own base and tool, and refused (naming the
file and the field) when it was identified for another arm, table, base, tool or sensor set."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from cell_fixtures import SmallCell, steady_drift

from cell.cli import main
from cell.run.inspect import T_cell_tcp
from cell.run.thermal_update import sensor_spec
from cell.sim.camserver import CameraServer
from cell.sim.session import SimCell
from cell.sim.world import WorldOptions
from robots.thermal.compensate import compensated_T_cell_tcp
from robots.thermal.model import ThermalModel
from robots.thermal.modelfile import save_model


def translation(xyz: list[float]) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = xyz
    return T


def _model(sc: SmallCell, n_sensors: int = 6, **changes) -> ThermalModel:
    arm = sc.cell.build_arm()
    model = ThermalModel(arm.dh, sensor_spec(n_sensors, 20.0), {"k_link2": 2e-5},
                         robot_model=sc.cell.robot.model, T_cell_base=arm.T_cell_base,
                         T_tool0_tcp=arm.T_tool0_tcp)  # fmt: skip
    return dataclasses.replace(model, **changes)


def test_compensated_pose_uses_the_given_base_and_tool(small_cell: SmallCell) -> None:
    arm = small_cell.cell.build_arm()
    other_tool = arm.T_tool0_tcp @ translation([0.0, 0.0, 0.05])
    model = _model(small_cell, T_tool0_tcp=other_tool, T_cell_base=np.eye(4))
    q, temps = np.asarray(small_cell.tour.stops[0].q), np.full(6, 20.0)
    T = T_cell_tcp(arm, model, q, temps)
    assert np.allclose(T, arm.fk(q, "tcp"), atol=1e-9)  # at the reference: nominal, cell's tool
    T_warm = compensated_T_cell_tcp(model, arm.T_cell_base, arm.T_tool0_tcp, q, temps + 10.0)
    assert np.allclose(T_cell_tcp(arm, model, q, temps + 10.0), T_warm)
    assert not np.allclose(T_warm, T, atol=1e-7)


def _run_cli(sc: SmallCell, model_path: Path, out: Path, port: str, camera: str) -> int:
    return main(["run", str(sc.tour_path), "--cell", str(sc.path), "--thermal", str(model_path),
                 "--port", port, "--camera", camera, "--out", str(out), "--yes", "--quiet",
                 "--no-record", "--settle-s", "0", "--reference-rounds", "0"])  # fmt: skip


@pytest.mark.parametrize(
    ("changes", "field"),
    [({"robot_model": "abb_irb4600_60_205"}, "robot_model"),
     ({"T_tool0_tcp": translation([0.0, 0.0, 0.3])}, "T_tool0_tcp"),
     ({"T_cell_base": translation([1.0, 0.0, 0.0])}, "T_cell_base"),
     ("dh", "dh.a_m")],
)  # fmt: skip
def test_model_for_another_cell_is_refused_before_connecting(
    small_cell: SmallCell, tmp_path: Path, capsys, changes, field
) -> None:
    if changes == "dh":
        arm = small_cell.cell.build_arm()
        a = np.asarray(arm.dh.a_m) + np.array([0.0, 0.01, 0, 0, 0, 0])
        changes = {"table": arm.dh.with_lengths(a, arm.dh.d_m)}
    path = tmp_path / "other_thermal.json"
    save_model(path, _model(small_cell, **changes))
    code = _run_cli(small_cell, path, tmp_path / "run", "/dev/null", "tcp://127.0.0.1:1")
    err = capsys.readouterr().err
    assert code == 2 and "other_thermal.json" in err and field in err, err
    assert "Traceback" not in err and not (tmp_path / "run").exists()


def test_model_with_other_sensor_count_is_refused(small_cell: SmallCell, tmp_path: Path,
                                                  capsys) -> None:  # fmt: skip
    path = tmp_path / "one_sensor.json"
    save_model(path, _model(small_cell, n_sensors=1))
    world = WorldOptions(speed=50.0, drift=steady_drift())
    with SimCell.start(small_cell.cell, world) as sim:
        cam = CameraServer(sim.camera).start()
        try:
            code = _run_cli(small_cell, path, tmp_path / "run", sim.url, cam.url)
        finally:
            cam.close()
    err = capsys.readouterr().err
    assert code == 2 and "one_sensor.json" in err and "sensors.names" in err, err
    assert not (tmp_path / "run" / "results.sqlite").exists()
