"""``holecell export ros2`` (cell/ros, docs/ros.md): bags read back by two readers that are not
ours (mcap-ros2-support decoding with the schemas stored in the bag, rosbags with its own ROS 2
Humble types) and compared with tour.json to 1e-9 rad; a simulated run's bag."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from cell_fixtures import SmallCell, steady_drift
from lxml import etree
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from rosbags.rosbag2 import Reader
from rosbags.typesys import Stores, get_typestore

from cell.cli import main
from cell.ros.samples import sample_at

RAD_TOL = 1e-9


def _mcap(bag: Path) -> dict[str, list]:
    """topic -> [(log time ns, decoded message)] with mcap-ros2-support."""
    out: dict[str, list] = {}
    with next(bag.glob("*.mcap")).open("rb") as fh:
        reader = make_reader(fh, decoder_factories=[DecoderFactory()])
        for _, channel, message, decoded in reader.iter_decoded_messages():
            out.setdefault(channel.topic, []).append((message.log_time, decoded))
    return out


def _rosbags(bag: Path, topics: tuple[str, ...]) -> dict[str, list]:
    store = get_typestore(Stores.ROS2_HUMBLE)
    out: dict[str, list] = {}
    with Reader(bag) as reader:
        conns = [c for c in reader.connections if c.topic in topics]
        for conn, t, raw in reader.messages(connections=conns):
            out.setdefault(conn.topic, []).append((t, store.deserialize_cdr(raw, conn.msgtype)))
    return out


def _urdf_joints(model: str) -> list[str]:
    urdf = Path(__file__).parents[2] / "robots" / "urdf" / f"{model}.urdf"
    tree = etree.parse(str(urdf))
    return [
        j.get("name") for j in tree.iter("joint") if j.get("type") in ("revolute", "continuous")
    ]


@pytest.fixture(scope="module")
def tour_bag(small_cell: SmallCell, tmp_path_factory: pytest.TempPathFactory) -> Path:
    bag = tmp_path_factory.mktemp("bags") / "tour_bag"
    args = [
        "export",
        "ros2",
        str(small_cell.tour_path),
        "-o",
        str(bag),
        "--cell",
        str(small_cell.path),
    ]
    assert main(args) == 0
    return bag


def test_trajectory_equals_tour_json_in_both_readers(small_cell: SmallCell, tour_bag: Path) -> None:
    tour = json.loads(small_cell.tour_path.read_text())
    rows = np.array(tour["trajectory"])
    names = tour["robot"]["joint_names"]
    assert names == _urdf_joints(tour["robot"]["model"])
    by_mcap = _mcap(tour_bag)
    by_rosbags = _rosbags(tour_bag, ("/joint_trajectory", "/joint_states"))
    for traj in (by_mcap["/joint_trajectory"][0][1], by_rosbags["/joint_trajectory"][0][1]):
        assert list(traj.joint_names) == names
        q = np.array([p.positions for p in traj.points])
        assert q.shape == rows.shape and np.max(np.abs(q - rows)) <= RAD_TOL
        t = [p.time_from_start.sec + p.time_from_start.nanosec * 1e-9 for p in traj.points]
        assert np.allclose(t, np.arange(len(rows)) * tour["dt"], atol=1e-9)
    display = by_mcap["/display_planned_path"][0][1]
    assert display.model_id == tour["robot"]["model"]
    shown = np.array([p.positions for p in display.trajectory[0].joint_trajectory.points])
    assert np.max(np.abs(shown - rows)) <= RAD_TOL
    start = display.trajectory_start.joint_state
    assert list(start.name) == names and np.allclose(start.position, tour["home_q"], atol=RAD_TOL)


def test_joint_states_at_100_hz(small_cell: SmallCell, tour_bag: Path) -> None:
    tour = json.loads(small_cell.tour_path.read_text())
    rows, dt = np.array(tour["trajectory"]), tour["dt"]
    states = _rosbags(tour_bag, ("/joint_states",))["/joint_states"]
    times = np.array([t for t, _ in states])
    assert np.all(np.diff(times) == 10_000_000)
    assert len(states) == int(np.floor((len(rows) - 1) * dt * 100 + 1e-9)) + 1
    for t_ns, msg in states[:: max(1, len(states) // 50)]:
        assert np.max(np.abs(msg.position - sample_at(rows, dt, t_ns * 1e-9))) <= RAD_TOL
        k = t_ns * 1e-9 / dt
        if abs(k - round(k)) < 1e-9:  # a row of tour.json itself
            assert np.max(np.abs(msg.position - rows[round(k)])) <= RAD_TOL


def test_stops_are_markers_and_the_base_is_placed(small_cell: SmallCell, tour_bag: Path) -> None:
    msgs = _mcap(tour_bag)
    markers = msgs["/inspection/stops"][0][1].markers
    stops = small_cell.tour.stops
    assert len(markers) == 2 * len(stops)
    texts = [m.text for m in markers if m.type == 9]
    assert texts == [f"{k + 1}: {s.hole_id}" for k, s in enumerate(stops)]
    arrows = [m for m in markers if m.type == 0]
    for m, s in zip(arrows, stops, strict=True):
        assert [m.points[0].x, m.points[0].y, m.points[0].z] == pytest.approx(s.tcp_pose["xyz"])
    tf = msgs["/tf_static"][0][1].transforms[0]
    assert tf.header.frame_id == "cell" and tf.child_frame_id == "base_link"


def test_an_existing_bag_is_not_overwritten(
    small_cell: SmallCell, tour_bag: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    before = sorted(p.stat().st_mtime_ns for p in tour_bag.iterdir())
    assert main(["export", "ros2", str(small_cell.tour_path), "-o", str(tour_bag)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "exists already" in err
    assert sorted(p.stat().st_mtime_ns for p in tour_bag.iterdir()) == before


def test_a_run_as_a_bag(small_cell: SmallCell, tmp_path: Path) -> None:
    from cell.link.client import ControllerClient, LinkOptions
    from cell.run.runner import Runner, RunOptions
    from cell.run.setup import start_run
    from cell.sim.session import SimCell
    from cell.sim.world import WorldOptions

    run_dir = tmp_path / "run"
    with SimCell.start(small_cell.cell, WorldOptions(speed=50.0, drift=steady_drift())) as sim:
        files = start_run(run_dir, small_cell.cell, small_cell.tour, "tour.json", sim.url)
        try:
            link = LinkOptions(response_timeout_s=0.05, retries=20, heartbeat_period_s=0.1)
            with ControllerClient(sim.url, link) as client:
                Runner(files.cell, files.tour, files.store, client, sim.camera,
                       RunOptions(settle_s=0.0, reference_rounds=0)).run()  # fmt: skip
            results = files.store.results()
        finally:
            files.store.close()
    bag = tmp_path / "run_bag"
    assert main(["export", "ros2", str(run_dir), "-o", str(bag)]) == 0
    msgs = _mcap(bag)
    measured = [r for r in results if r.measured]
    assert measured
    captures = msgs["/inspection/capture_states"]
    assert len(captures) == len(results)
    by_hole = {r.hole_id: r for r in results}
    for _, js in captures:
        assert np.max(np.abs(np.array(js.position) - by_hole[js.header.frame_id].q_rad)) <= RAD_TOL
    discs = [m for m in msgs["/inspection/holes"][0][1].markers if m.type == 3]
    assert len(discs) == len(measured)
    assert sorted(d.scale.x for d in discs) == pytest.approx(sorted(r.diameter_m for r in measured))
    rows = np.array(json.loads(small_cell.tour_path.read_text())["trajectory"])
    traj = msgs["/joint_trajectory"][0][1]
    assert np.max(np.abs(np.array([p.positions for p in traj.points]) - rows)) <= RAD_TOL
