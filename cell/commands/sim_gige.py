"""The simulated head of ``holecell sim``: served over TCP (``tcp://``) or as two GigE Vision
fake cameras (``--camera-transport gige``, :mod:`cell.sim.gige_head`), with injected faults."""

from __future__ import annotations

import argparse
import ipaddress
from typing import Any

from cell.errors import CellError
from cell.sim.camera import SimCamera
from cell.sim.camserver import CameraServer
from cell.sim.gige_head import FAULT_KINDS, GigeFaults


def _ips(text: str) -> tuple[str, str]:
    ips = tuple(p.strip() for p in text.split(","))
    try:
        if len(ips) != 2 or ips[0] == ips[1]:
            raise ValueError
        for ip in ips:
            ipaddress.IPv4Address(ip)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: give two different IPv4 addresses, "
                                         "LEFT,RIGHT") from None  # fmt: skip
    return ips  # type: ignore[return-value]


def _fault(text: str) -> tuple[str, frozenset[int]]:
    kind, _, stops = text.partition(":")
    try:
        if kind not in FAULT_KINDS:
            raise ValueError
        keys = frozenset(int(k) for k in stops.split(","))
        if min(keys) < 0:
            raise ValueError
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: expected KIND:STOP[,STOP...] with KIND "
                                         f"one of {', '.join(FAULT_KINDS)}") from None  # fmt: skip
    return kind, keys


def add_camera_arguments(p: argparse.ArgumentParser) -> None:
    """``--camera-transport``, ``--camera-ip`` and ``--camera-fault``."""
    p.add_argument("--camera-transport", choices=("tcp", "gige"), default="tcp",
                   help="tcp: the head on a local TCP port; gige: two GigE Vision fake cameras "
                        "(Aravis) at --camera-ip, over real GVCP/GVSP; run it inside a private "
                        "network namespace (docs/real_cell.md)")  # fmt: skip
    p.add_argument("--camera-ip", type=_ips, default=("127.0.0.1", "127.0.0.2"),
                   metavar="LEFT,RIGHT", help="addresses of the two fake cameras (gige; "
                   "default 127.0.0.1,127.0.0.2)")  # fmt: skip
    p.add_argument("--camera-fault", type=_fault, action="append", default=[],
                   metavar="KIND:STOPS", help="gige: the right camera's frame at these stops "
                   "(0-based) is dropped, incomplete or a mismatch (its previous frame); "
                   "repeatable")  # fmt: skip


def serve_head(camera: SimCamera, args: argparse.Namespace) -> Any:
    """Start serving ``camera`` as ``args`` ask; the server has ``url`` and ``close()``."""
    if args.camera_transport == "tcp":
        if args.camera_fault:
            raise CellError("--camera-fault needs --camera-transport gige")
        return CameraServer(camera).start()
    from cell.sim.gige_head import GigeHead

    faults = GigeFaults({k: v for k, v in args.camera_fault})
    return GigeHead.for_camera(camera, args.camera_ip, faults)
