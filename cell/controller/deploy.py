"""Deploy the RAPID module: upload ``HolecellLink.mod`` (with the cell's link settings) to the
controller's RAM disk, load it into the motion task, reset the program pointer, start it, and
wait until it answers on the link."""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from dataclasses import dataclass, field

from cell.controller.errors import ControllerError
from cell.controller.manager import ControllerManager

log = logging.getLogger(__name__)

MODULE_FILE = "HolecellLink.mod"


@dataclass
class DeployReport:
    """What the deployment did: the module's path on the controller, the steps in order and
    how long the link took to answer (s)."""

    module_path: str = ""
    steps: list[str] = field(default_factory=list)
    link_answer: str = ""
    link_wait_s: float = 0.0


def deploy(
    manager: ControllerManager,
    module_text: str,
    answers: Callable[[], str],
    task: str = "T_ROB1",
    link_timeout_s: float = 30.0,
) -> DeployReport:
    """Run the steps in order; ``answers()`` tries the link once and returns the controller's
    identity, raising an error while it does not answer yet."""
    report = DeployReport()
    state = manager.state()
    if state.controller != "motoron":
        why = (f"motors are off (controller state {state.controller}, mode {state.opmode}): "
               "switch the motors on, then deploy again")  # fmt: skip
        raise ControllerError(manager.url, "start", why)
    if state.execution == "running":
        manager.stop()
        report.steps.append("stop")
    report.module_path = manager.upload(MODULE_FILE, module_text.encode())
    report.steps.append("upload")
    manager.load_module(report.module_path, task)
    report.steps.append("loadmod")
    manager.reset_pp()
    report.steps.append("resetpp")
    manager.start(task)
    report.steps.append("start")
    t0 = time.monotonic()
    last = ""
    while True:
        try:
            report.link_answer = answers()
            break
        except Exception as exc:  # the module is still opening its port
            last = str(exc)
        if time.monotonic() - t0 > link_timeout_s:
            raise ControllerError(manager.url, "link",
                                  f"the module does not answer after {link_timeout_s:g} s: "
                                  f"{last}")  # fmt: skip
        problem = manager.state().problem()
        if problem is not None:
            raise ControllerError(manager.url, "link", f"the controller stopped: {problem}")
        time.sleep(0.2)
    report.link_wait_s = time.monotonic() - t0
    report.steps.append("link")
    return report
