"""Motion and I/O signal built-ins: MoveAbsJ, CJointT, StopMove, StartMove, ClearPath, AliasIO,
AInput (RAPID reference manual). The arm and the signals are the host's; a move is handed over
with its joint target (deg), its time (\\T, s) and whether it ends in a fine point."""

from __future__ import annotations

from cell.rapid.interp.builtins.base import Arg, Builtin, Opt
from cell.rapid.interp.errors import RapidRunError
from cell.rapid.interp.rtypes import F32, Record, default


def _move_abs_j(
    st,
    line,
    jt: Record,
    speed: Record,
    zone: Record,
    tool: Record,
    conc=False,
    id=None,
    noeoffs=False,
    v=None,
    t=None,
    z=None,
    inpos=None,
    wobj=None,
):
    q = [float(jt.f["robax"].f[f"rax_{i}"]) for i in range(1, 7)]
    if t is not None and t < 0:
        raise RapidRunError("ERR_ARGVALERR", f"\\T {float(t):g} s", line)
    st.host.move_abs_j(q, None if t is None else float(t), bool(zone.f["finep"]), bool(conc))


def _cjointt(st, line, taskref=None, taskname=None):
    jt = default("jointtarget")
    for i, v in enumerate(st.host.joints_deg(), start=1):
        jt.f["robax"].f[f"rax_{i}"] = F32(v)
    for c in "abcdef":
        jt.f["extax"].f[f"eax_{c}"] = F32(9e9)
    return jt


def _stop_move(st, line, quick=False, allmotiontasks=False):
    st.host.stop_move()


def _start_move(st, line, allmotiontasks=False):
    st.host.start_move()


def _clear_path(st, line):
    st.host.clear_path()


def _alias_io(st, line, name, ref):
    c, k = ref
    if not st.host.has_signal(name):
        raise RapidRunError("ERR_ALIASIO_DEF", f"no signal {name!r} in the I/O configuration",
                            line)  # fmt: skip
    c[k].obj = name


def _ainput(st, line, h):
    if h.obj is None:
        raise RapidRunError("ERR_NORUNUNIT", f"signal {h.name} is not connected (AliasIO)", line)
    return F32(st.host.analog_input(h.obj))


BUILTINS = [
    Builtin("MoveAbsJ", "proc",
            (Arg("ToJointPos", ("jointtarget",)), Arg("Speed", ("speeddata",)),
             Arg("Zone", ("zonedata",)), Arg("Tool", ("tooldata",))), _move_abs_j,
            (Opt("Conc", after=0), Opt("ID", ("identno",), after=1), Opt("NoEOffs", after=1),
             Opt("V", ("num",), after=2, group="speed"), Opt("T", ("num",), after=2, group="speed"),
             Opt("Z", ("num",), after=3), Opt("Inpos", ("stoppointdata",), after=3),
             Opt("WObj", ("wobjdata",), after=4)), page="Instructions: MoveAbsJ"),
    Builtin("CJointT", "func", (), _cjointt,
            (Opt("TaskRef", ("taskid",), group="task"), Opt("TaskName", ("string",), group="task")),
            ret="jointtarget", page="Functions: CJointT"),
    Builtin("StopMove", "proc", (), _stop_move, (Opt("Quick"), Opt("AllMotionTasks")),
            page="Instructions: StopMove"),
    Builtin("StartMove", "proc", (), _start_move, (Opt("AllMotionTasks"),),
            page="Instructions: StartMove"),
    Builtin("ClearPath", "proc", (), _clear_path, page="Instructions: ClearPath"),
    Builtin("AliasIO", "proc", (Arg("FromSignal", ("string",)),
            Arg("ToSignal", ("signalai",), True)), _alias_io, page="Instructions: AliasIO"),
    Builtin("AInput", "func", (Arg("Signal", ("signalai",)),), _ainput, ret="num",
            page="Functions: AInput"),
]  # fmt: skip
