"""A whole simulated cell in one object: truth, controller served on a pty or socket, stereo head.

``SimCell(cell, ...)`` builds :class:`SimWorld`, :class:`SimController`, :class:`SimServer` and
:class:`SimCamera`; ``url`` is the port the runner opens, ``camera`` the head it triggers.
"""

from __future__ import annotations

from dataclasses import dataclass

from cell.camera import cell_stereo
from cell.config import CellConfig
from cell.sim.camera import SimCamera
from cell.sim.controller import SimController
from cell.sim.faults import FaultPlan
from cell.sim.server import SimServer
from cell.sim.world import SimWorld, WorldOptions
from measure.synth import RenderOptions


@dataclass
class SimCell:
    """A running simulated cell. Close it (or use ``with``) to stop the controller thread."""

    world: SimWorld
    controller: SimController
    server: SimServer
    camera: SimCamera

    @classmethod
    def start(
        cls,
        cell: CellConfig,
        world: WorldOptions | None = None,
        faults: FaultPlan | None = None,
        transport: str = "pty",
        link_timeout_s: float = 1.0,
        render: RenderOptions | None = None,
        controller: str = "python",
    ) -> SimCell:
        """Build and start the simulated cell. ``controller`` "python" serves
        :class:`SimController`; "rapid" the shipped RAPID module in the interpreter
        (:class:`cell.sim.rapid_controller.RapidController`)."""
        faults = faults or FaultPlan()
        w = SimWorld(cell, world)
        if controller == "rapid":
            return cls._start_rapid(cell, w, faults, transport, link_timeout_s, render)
        if controller != "python":
            raise ValueError(f"controller {controller!r} must be 'python' or 'rapid'")
        ctrl = SimController(
            w.clock,
            w.temperatures,
            cell.robot.model,
            cell.home_q(),
            estop_at_stop=faults.estop_at_stop,
            link_timeout_s=link_timeout_s,
        )
        server = SimServer(ctrl, faults, transport).start()
        try:
            cam = SimCamera(w, ctrl, cell_stereo(cell), faults.missing_holes, render, faults.seed)
        except BaseException:
            server.close()
            raise
        return cls(w, ctrl, server, cam)

    @classmethod
    def _start_rapid(cls, cell, w, faults, transport, link_timeout_s, render) -> SimCell:
        from cell.sim.rapid_controller import RapidController

        ctrl = RapidController(w.clock, w.temperatures, cell.robot.model, cell.home_q(), faults,
                               transport, faults.estop_at_stop, link_timeout_s).start()  # fmt: skip
        try:
            cam = SimCamera(w, ctrl, cell_stereo(cell), faults.missing_holes, render, faults.seed)
        except BaseException:
            ctrl.close()
            raise
        return cls(w, ctrl, ctrl, cam)

    @property
    def url(self) -> str:
        """The port URL the runner opens."""
        return self.server.url

    def close(self) -> None:
        """Stop the controller and release the port."""
        self.server.close()

    def __enter__(self) -> SimCell:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
