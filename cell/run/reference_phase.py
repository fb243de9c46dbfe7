"""The runner's reference phase: rounds over the reference targets while the arm warms, the
thermal model identified from them (:class:`cell.run.runner.Runner`'s base)."""

from __future__ import annotations

import time
from collections import deque
from concurrent.futures import Future

import numpy as np

from cell.camera.backend import computing
from cell.camera.errors import PairError
from cell.link import messages as m
from cell.link.motion import Motion
from cell.referencing.detection import detect_pair, label_circles
from cell.run.ahead import STOPS_AHEAD
from cell.run.reference import target_of
from cell.run.thermal_record import remember_model
from measure import MeasurementError, measure_hole
from planner import Tour

#: the arm is at a joint vector if every joint is within this (rad; half the controller's
#: on-path tolerance of 1e-3 degrees)
HOME_TOL_RAD = float(np.deg2rad(0.5e-3))


class ReferencePhase(Motion):
    """The reference rounds and the thermal identification; uses the runner's ``tour``,
    ``reference_tour``, ``camera``, ``ahead`` (its captures), ``stereo``, ``codes``,
    ``thermal``, ``store``, ``options``, ``progress``, ``model`` and ``model_id``."""

    def _home_for_reference(self) -> None:
        """Bring the arm home if it is elsewhere (a resumed run stopped at a hole, between holes
        or on the way to a reference target): the reference trajectory starts at home, and a
        controller refuses to load a trajectory the arm is not on, so the arm goes home along
        whichever of the two tours it stands on."""
        home = np.asarray(self.reference_tour.trajectory[0], float)
        st = self._call("status", self.client.status)
        if np.max(np.abs(st.q_rad - home)) <= HOME_TOL_RAD:
            return
        tours = {"inspection": self.tour, "reference": self.reference_tour}
        name = min(tours, key=lambda n: _distance_to_path_rad(tours[n], st.q_rad))
        self.store.event("motion", f"the arm is off home: homing along the {name} tour before "
                                   "the reference targets")  # fmt: skip
        self._load(tours[name])
        self._move(len(tours[name].stops), "home before the reference targets")

    def _reference_phase(self) -> None:
        tour = self.reference_tour
        self._load(tour)
        for rnd in range(self.options.reference_rounds):
            st_start = self._call("status", self.client.status)
            t_start = st_start.time_s
            if self.thermal.cold_degC is None:  # the cold state: before the arm first moves
                self.thermal.cold_degC = tuple(float(v) for v in st_start.temperatures_c)
                self.store.set_thermal_reference(self.thermal.cold_degC)
            self.progress("round", {"round": rnd, "time_s": t_start})
            pending: deque = deque()  # views captured, measured once the arm is further on
            for k, s in enumerate(tour.stops):
                self._move(k, f"reference {s.hole_id}")
                st = self._settled_status()
                pending.append((rnd, s.hole_id, st, self.ahead.capture(k, s.hole_id, keep=False)))
                while len(pending) > STOPS_AHEAD:
                    self._reference_view(*pending.popleft())
            while pending:
                self._reference_view(*pending.popleft())
            self._move(len(tour.stops), "reference home")
            if rnd + 1 < self.options.reference_rounds:
                self._wait_controller_time(t_start + self.options.reference_interval_s)

    def _reference_view(self, rnd: int, view_id: str, st: m.Status, pair: Future) -> None:
        """Measure one reference view's target (the pair to come, :mod:`cell.run.ahead`) and
        record it, or record why not."""
        with computing(self.camera):  # the arm waits while the computer works
            try:
                pair, _, dets = pair.result()
                exclude = None
                if self.codes:  # the markers' labels are not the reference target
                    if dets is None:
                        dets = detect_pair(pair.left, pair.right, self.stereo, self.codes)
                    exclude = label_circles(dets)
                meas = measure_hole(pair.left, pair.right, self.stereo, exclude=exclude)
            except (MeasurementError, PairError) as exc:
                self.store.event("reference", f"{view_id}: not measured: {exc}")
                return
        p_tcp = self._T_head_left[:3, :3] @ meas.center_m + self._T_head_left[:3, 3]
        row = (st.time_s, target_of(view_id), st.q_rad, st.temperatures_c, p_tcp,
               self._round0 + rnd)  # fmt: skip
        self.store.record_reference(row[5], *row[:5])
        self.thermal.add(*row)
        self.progress("reference", {"round": rnd, "target": view_id})

    def _wait_controller_time(self, t_s: float) -> None:
        while self._call("status", self.client.status).time_s < t_s:
            time.sleep(0.01)

    def _identify(self) -> str:
        model = self.thermal.identify()
        if model is None:
            msg = f"thermal model not updated: {self.thermal.refusal}"
            if self.model is not None and self.thermal.rows:
                rms = self.thermal.check(self.model)
                msg += f"; the given model predicts the reference targets to {rms * 1e6:.1f} um RMS"
        else:
            self.model = model
            r = self.thermal.result
            self.model_id = remember_model(self.store, model, f"identified from {r.n_rows} rows")
            msg = (
                f"thermal model identified from {r.n_rows} rows: terms {', '.join(r.report.kept)};"
                f" residual {r.residual_rms_m * 1e6:.1f} um"
                f" (before {r.residual_rms_before_m * 1e6:.1f} um)"
            )
        self.store.event("thermal", msg)
        return msg


def _distance_to_path_rad(tour: Tour, q_rad: np.ndarray) -> float:
    """Largest joint difference (rad) between ``q_rad`` and the nearest sample of the tour."""
    rows = np.asarray(tour.trajectory, float)
    return float(np.min(np.max(np.abs(rows - q_rad), axis=1)))
