"""Clock and time built-ins: ClkReset, ClkStart, ClkStop, ClkRead, WaitTime (RAPID reference
manual). A clock reads the host's time source of its variable's name; ClkRead gives num seconds
with the manual's resolution of 0.001 s."""

from __future__ import annotations

from cell.rapid.interp.builtins.base import Arg, Builtin, Opt
from cell.rapid.interp.errors import RapidRunError
from cell.rapid.interp.rtypes import F32


def _state(h):
    if h.obj is None:
        h.obj = {"acc": 0.0, "since": None}
    return h.obj


def _reset(st, line, ref):
    c, k = ref
    h = c[k]
    s = _state(h)
    s["acc"] = 0.0
    if s["since"] is not None:
        s["since"] = st.host.now_s(h.name)


def _start(st, line, ref):
    c, k = ref
    s = _state(c[k])
    if s["since"] is None:
        s["since"] = st.host.now_s(c[k].name)


def _stop(st, line, ref):
    c, k = ref
    s = _state(c[k])
    if s["since"] is not None:
        s["acc"] += st.host.now_s(c[k].name) - s["since"]
        s["since"] = None


def _read(st, line, h, highres=False):
    s = _state(h)
    t = s["acc"] + (0.0 if s["since"] is None else st.host.now_s(h.name) - s["since"])
    if t > 4294967.0:
        raise RapidRunError("ERR_NUMOVERFLOW", "clock overflow", line)
    return F32(t if highres else round(t, 3))


def _wait(st, line, seconds, inpos=False):
    if seconds < 0:
        raise RapidRunError("ERR_ARGVALERR", f"WaitTime {float(seconds):g} s", line)
    st.host.wait(float(seconds))


BUILTINS = [
    Builtin("ClkReset", "proc", (Arg("Clock", ("clock",), True),), _reset,
            page="Instructions: ClkReset"),
    Builtin("ClkStart", "proc", (Arg("Clock", ("clock",), True),), _start,
            page="Instructions: ClkStart"),
    Builtin("ClkStop", "proc", (Arg("Clock", ("clock",), True),), _stop,
            page="Instructions: ClkStop"),
    Builtin("ClkRead", "func", (Arg("Clock", ("clock",)),), _read,
            (Opt("HighRes", after=1),), ret="num", page="Functions: ClkRead"),
    Builtin("WaitTime", "proc", (Arg("Time", ("num",)),), _wait, (Opt("InPos", after=0),),
            page="Instructions: WaitTime"),
]  # fmt: skip
