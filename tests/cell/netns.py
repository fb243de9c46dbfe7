"""Run a test inside a private network namespace (``unshare -n``), where loopback carries
127.0.0.1 and 127.0.0.2 and nothing else exists: every test that starts a fake GigE Vision
camera runs there, so no packet can leave the machine (Aravis fakes answer discovery
broadcasts; discovery itself is never called).

``@in_netns`` re-runs the decorated test in a child pytest under ``unshare -n`` (as root, as
the suite and CI run) and fails with the child's output; inside the child the body runs.
"""

from __future__ import annotations

import functools
import os
import shutil
import socket
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

ENV = "HOLECELL_IN_NETNS"
SETUP = "ip link set lo up && ip addr add 127.0.0.2/8 dev lo"


def in_private_netns() -> bool:
    """This process sees no network interface but loopback (a fresh ``unshare -n``)."""
    return [name for _, name in socket.if_nameindex()] == ["lo"]


def netns_problem() -> str | None:
    """Why a test cannot run in a private namespace here, or None."""
    if shutil.which("unshare") is None or shutil.which("ip") is None:
        return "unshare or ip (util-linux, iproute2) not installed"
    probe = subprocess.run(["unshare", "-n", "sh", "-c", SETUP], capture_output=True, text=True)
    if probe.returncode != 0:
        return f"unshare -n refused (run as root): {probe.stderr.strip()}"
    try:
        import gi

        gi.require_version("Aravis", "0.8")
    except (ImportError, ValueError) as exc:
        return f"Aravis 0.8 / PyGObject missing ({exc}): make test installs them"
    return None


@functools.cache
def _problem() -> str | None:
    return netns_problem()


def in_netns(test: Callable[..., Any]) -> Callable[..., Any]:
    """Run ``test`` in a child pytest inside ``unshare -n`` (see module doc)."""

    @functools.wraps(test)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        if os.environ.get(ENV) == "1":
            assert in_private_netns(), "a fake camera outside a private network namespace"
            return test(*args, **kwargs)
        if (why := _problem()) is not None:
            if os.environ.get("CI"):  # CI runs as root with make's packages: it must run
                pytest.fail(f"GigE test cannot run: {why}")
            pytest.skip(why)
        node = os.environ["PYTEST_CURRENT_TEST"].rsplit(" ", 1)[0]
        root = Path(__file__).resolve().parents[2]
        cmd = (f"{SETUP} && exec {sys.executable} -m pytest -q -p no:cacheprovider -x "
               f"-o addopts='' -p no:xdist '{node}'")  # fmt: skip
        env = {**os.environ, ENV: "1"}
        env.pop("PYTEST_XDIST_WORKER", None)
        r = subprocess.run(["unshare", "-n", "sh", "-c", cmd], cwd=root, env=env,
                           capture_output=True, text=True, timeout=600)  # fmt: skip
        assert r.returncode == 0, f"in unshare -n:\n{r.stdout[-6000:]}\n{r.stderr[-3000:]}"
        return None

    return wrapper
