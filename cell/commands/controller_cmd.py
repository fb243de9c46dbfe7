"""``holecell controller deploy``: put the RAPID module on an ABB controller over Robot Web
Services and start it (docs/real_cell.md)."""

from __future__ import annotations

import argparse
import os
from collections.abc import Callable
from typing import Any

from cell.commands.argtypes import positive_float
from cell.config import load_cell
from cell.controller.deploy import deploy
from cell.controller.rws1 import Rws1Manager
from cell.errors import CellError
from cell.link.client import ControllerClient
from cell.rapid.module import link_module, link_settings

PASSWORD_ENV = "HOLECELL_RWS_PASSWORD"
#: RobotWare 6's factory user (its password is the factory one unless changed)
DEFAULT_USER = "Default User"


def add_rws_arguments(p: argparse.ArgumentParser, prefix: str = "") -> None:
    """``--rws URL``, ``--{prefix}user``, ``--{prefix}password`` (the password also from
    ``HOLECELL_RWS_PASSWORD``)."""
    p.add_argument("--rws", metavar="http://HOST[:PORT]", help="the controller's Robot Web "
                   "Services (RWS 1.0, RobotWare 6)")  # fmt: skip
    p.add_argument(f"--{prefix}user", dest="rws_user", default=DEFAULT_USER,
                   help=f"RWS user (default {DEFAULT_USER!r})")  # fmt: skip
    p.add_argument(f"--{prefix}password", dest="rws_password", default=None,
                   help=f"RWS password (better: the environment variable {PASSWORD_ENV}; "
                        "default: the factory password); never logged or stored")  # fmt: skip


def add_rws_trigger_argument(p: argparse.ArgumentParser) -> None:
    """``--rws-trigger SIGNAL`` of ``holecell run``."""
    p.add_argument("--rws-trigger", metavar="SIGNAL", default=None,
                   help="with --rws and a gige camera with trigger=line0..3: pulse this "
                        "controller digital output (NAME or NETWORK/UNIT/NAME), wired to both "
                        "cameras' trigger input, for each capture")  # fmt: skip


def trigger_pulse(client: Any, args: argparse.Namespace) -> Callable[[], None] | None:
    """The hardware trigger of ``--rws-trigger`` (a digital output pulsed over RWS), or None."""
    signal = getattr(args, "rws_trigger", None)
    if signal is None:
        return None
    if not getattr(args, "rws", None):
        raise CellError("--rws-trigger needs --rws")
    manager = client.watch.manager
    return lambda: manager.pulse(signal)


def rws_manager(args: argparse.Namespace) -> Rws1Manager:
    """The RWS 1.0 manager of ``args.rws`` with the user and password of ``args``."""
    password = args.rws_password or os.environ.get(PASSWORD_ENV) or "robotics"
    return Rws1Manager(args.rws, args.rws_user, password)


def watched_client(client: ControllerClient, args: argparse.Namespace) -> Any:
    """``client``, or with ``--rws`` the same client watched over RWS: a controller whose
    motors go off, that is e-stopped or whose RAPID execution stops ends the run at its next
    request, with the state in the run log (:mod:`cell.controller.watch`)."""
    if not getattr(args, "rws", None):
        return client
    from cell.controller.watch import ControllerWatch, WatchedClient

    manager = rws_manager(args)
    try:
        watch = ControllerWatch(manager).start()
    except BaseException:
        manager.close()
        raise
    return WatchedClient(client, watch)


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``controller`` with ``deploy``."""
    p = sub.add_parser("controller", help="manage the robot controller (deploy the module)")
    verbs = p.add_subparsers(dest="verb", metavar="VERB", required=True)
    d = verbs.add_parser(
        "deploy",
        help="upload, load and start HolecellLink.mod over RWS",
        description=(
            "Writes HolecellLink.mod with the link settings for CELL and --port (socket://"
            "ADDRESS:PORT: RAPID socket messaging, option 616-1 or 672-1; else the serial "
            "channel com1:) to the controller's RAM disk, loads it into --task (replacing the "
            "module of that name), resets the program pointer, starts RAPID and waits until "
            "the module answers on the link at --port."
        ),
    )
    add_rws_arguments(d)
    d.add_argument("--cell", default=None, help="cell file (default: built-in)")
    d.add_argument("--port", required=True, help="the link as holecell run opens it")
    d.add_argument("--task", default="T_ROB1", help="RAPID motion task (default T_ROB1)")
    d.add_argument("--name", default="irc5-holecell", help="controller name the module reports")
    d.add_argument("--link-timeout-s", type=positive_float, default=30.0,
                   help="wait this long for the module to answer on the link")  # fmt: skip
    d.set_defaults(handler=run_deploy)


def _answers(port: str) -> str:
    client = ControllerClient(port)
    try:
        ident = client.connect()
    finally:
        client.close()
    return f"{ident.controller} ({ident.robot_model})"


def run_deploy(args: argparse.Namespace) -> int:
    """Handler of ``holecell controller deploy``."""
    if not args.rws:
        raise CellError("give --rws http://HOST[:PORT]")
    cell = load_cell(args.cell)
    text = link_module(link_settings(cell.robot.model, args.port, args.name))
    manager = rws_manager(args)
    try:
        report = deploy(manager, text, lambda: _answers(args.port), args.task,
                        args.link_timeout_s)  # fmt: skip
    finally:
        manager.close()
    print(f"module      {report.module_path} in {args.task}")
    print(f"steps       {' -> '.join(report.steps)}")
    print(f"link        {args.port}: {report.link_answer} after {report.link_wait_s:.1f} s")
    return 0
