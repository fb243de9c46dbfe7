"""The simulated arm behind the interpreted module's MoveAbsJ: a queue of joint moves (deg),
each linear in joint space over its time (``\\T``, simulation s) from where the previous one
ends. ``\\Conc`` returns at once while the queue holds fewer than ``depth`` moves (RAPID: at
most 5 consecutive concurrent moves); a move without it returns on arrival. Zones (corner
paths) and the servo's acceleration are not modelled."""

from __future__ import annotations

import time
from collections import deque
from collections.abc import Callable

import numpy as np

from cell.sim.world import SimClock

#: joint speed of a move without \T (deg/s)
DEFAULT_DEG_PER_S = 100.0


class SimArm:
    """Joint positions (deg) in simulation time; ``check()`` runs while a move waits."""

    def __init__(self, clock: SimClock, q0_deg: np.ndarray, check: Callable[[], None],
                 depth: int = 5) -> None:  # fmt: skip
        self.clock, self.check, self.depth = clock, check, depth
        self._q = np.asarray(q0_deg, dtype=float).copy()
        self._segs: deque[tuple[np.ndarray, np.ndarray, float, float]] = deque()

    def _advance(self, now: float) -> None:
        while self._segs and self._segs[0][3] <= now:
            self._q = self._segs.popleft()[1]

    def position(self) -> np.ndarray:
        """Joints now (deg)."""
        now = self.clock.now()
        self._advance(now)
        if not self._segs:
            return self._q.copy()
        q0, q1, t0, t1 = self._segs[0]
        if now <= t0:
            return q0.copy()
        f = (now - t0) / (t1 - t0)
        return q0 + f * (q1 - q0)

    def set_position(self, q_deg: np.ndarray) -> None:
        self._segs.clear()
        self._q = np.asarray(q_deg, dtype=float).copy()

    def move(self, q_deg: list[float], time_s: float | None, fine: bool, conc: bool) -> None:
        now = self.clock.now()
        self._advance(now)
        q1 = np.asarray(q_deg, dtype=float)
        if self._segs:
            q0, t0 = self._segs[-1][1], self._segs[-1][3]
        else:
            q0, t0 = self.position(), now
        dur = time_s if time_s is not None else float(np.abs(q1 - q0).max()) / DEFAULT_DEG_PER_S
        self._segs.append((q0, q1, t0, t0 + dur))
        if conc:
            self._wait(lambda: len(self._segs) <= self.depth)
        else:
            self._wait(lambda: not self._segs)

    def _wait(self, done: Callable[[], bool]) -> None:
        while True:
            self._advance(self.clock.now())
            if done():
                return
            self.check()
            t_end = self._segs[0][3]
            time.sleep(min(0.002, max(self.clock.wall_for(t_end - self.clock.now()), 0.0)))

    def halt(self) -> None:
        """StopMove + ClearPath: hold where the arm is, forget the queued moves."""
        self._q = self.position()
        self._segs.clear()
