"""Socket messaging built-ins: SocketCreate, SocketBind, SocketListen, SocketAccept,
SocketConnect, SocketSend, SocketReceive, SocketClose, SocketGetStatus (RAPID reference
manual; RobotWare option 616-1 PC Interface or 672-1 Socket Messaging on IRC5, included in
RobotWare 7). Timeouts raise ERR_SOCK_TIMEOUT, a closed peer ERR_SOCK_CLOSED."""

from __future__ import annotations

from cell.rapid.interp.builtins.base import Arg, Builtin, Opt
from cell.rapid.interp.consts import SOCKET_STATES
from cell.rapid.interp.errors import RapidRunError
from cell.rapid.interp.rtypes import F32, RawBytes

#: \Time default of SocketAccept, SocketConnect and SocketReceive (s)
DEFAULT_TIME_S = 60.0


def _sock(h, line: int):
    if h.obj is None:
        raise RapidRunError("ERR_SOCK_CLOSED", f"socket {h.name} is not created", line)
    return h.obj


def _run(line: int, fn, *a):
    try:
        return fn(*a)
    except RapidRunError as e:
        e.line = e.line or line
        raise


def _create(st, line, ref, udp=False):
    c, k = ref
    if c[k].obj is not None:
        raise RapidRunError("ERR_SOCK_ADDR_INUSE", f"socket {c[k].name} already created", line)
    c[k].obj = st.host.socket()


def _bind(st, line, h, address, port):
    _run(line, _sock(h, line).bind, address, int(port))


def _listen(st, line, h):
    _run(line, _sock(h, line).listen)


def _accept(st, line, h, ref, clientaddress=None, time=None):
    st.host.poll()
    c, k = ref
    if c[k].obj is not None:
        raise RapidRunError("ERR_SOCK_ADDR_INUSE", f"client socket {c[k].name} is in use", line)
    t = DEFAULT_TIME_S if time is None else float(time)
    c[k].obj = _run(line, _sock(h, line).accept, t)


def _connect(st, line, h, address, port, time=None):
    t = DEFAULT_TIME_S if time is None else float(time)
    _run(line, _sock(h, line).connect, address, int(port), t)


def _send(st, line, h, str=None, rawdata=None, data=None, noofbytes=None):
    st.host.poll()
    if str is not None:
        payload = str.encode("latin-1")
    elif rawdata is not None:
        payload = rawdata.valid()
    else:
        payload = bytes(int(b) for b in data.v)
    if noofbytes is not None:
        n = int(noofbytes)
        if not 1 <= n <= len(payload):
            raise RapidRunError("ERR_OUTOFBND", f"NoOfBytes {n} of {len(payload)}", line)
        payload = payload[:n]
    _run(line, _sock(h, line).send, payload)


def _receive(
    st, line, h, str=None, rawdata=None, data=None, readnoofbytes=None, norecbytes=None, time=None
):
    st.host.poll()
    ref = str if str is not None else rawdata if rawdata is not None else data
    c, k = ref
    cap = 1024 if rawdata is not None else 80 if str is not None else len(c[k].v)
    n = cap if readnoofbytes is None else int(readnoofbytes)
    if not 1 <= n <= cap:
        raise RapidRunError("ERR_OUTOFBND", f"ReadNoOfBytes {n} outside 1..{cap}", line)
    t = DEFAULT_TIME_S if time is None else float(time)
    got = _run(line, _sock(h, line).receive, n, readnoofbytes is not None, t)
    if rawdata is not None:
        raw = RawBytes()
        raw.data[: len(got)], raw.n = got, len(got)
        c[k] = raw
    elif str is not None:
        c[k] = got.decode("latin-1")
    else:
        for i, b in enumerate(got):
            c[k].v[i] = b
    if norecbytes is not None:
        nc, nk = norecbytes
        nc[nk] = F32(len(got))


def _close(st, line, ref):
    c, k = ref
    if c[k].obj is not None:
        c[k].obj.close()
        c[k].obj = None


def _status(st, line, h):
    return F32(SOCKET_STATES["SOCKET_CLOSED" if h.obj is None else h.obj.status()])


_S = Arg("Socket", ("socketdev",))
BUILTINS = [
    Builtin("SocketCreate", "proc", (Arg("Socket", ("socketdev",), True),), _create,
            (Opt("UDP", after=1),), page="Instructions: SocketCreate"),
    Builtin("SocketBind", "proc", (_S, Arg("LocalAddress", ("string",)),
            Arg("LocalPort", ("num",))), _bind, page="Instructions: SocketBind"),
    Builtin("SocketListen", "proc", (_S,), _listen, page="Instructions: SocketListen"),
    Builtin("SocketAccept", "proc", (_S, Arg("ClientSocket", ("socketdev",), True)), _accept,
            (Opt("ClientAddress", ("string",), after=2, var=True),
             Opt("Time", ("num",), after=2)), page="Instructions: SocketAccept"),
    Builtin("SocketConnect", "proc", (_S, Arg("Address", ("string",)), Arg("Port", ("num",))),
            _connect, (Opt("Time", ("num",), after=3),), page="Instructions: SocketConnect"),
    Builtin("SocketSend", "proc", (_S,), _send,
            (Opt("Str", ("string",), after=1, group="what"),
             Opt("RawData", ("rawbytes",), after=1, group="what"),
             Opt("Data", ("byte",), after=1, group="what"),
             Opt("NoOfBytes", ("num",), after=1)), need_one=("what",),
            page="Instructions: SocketSend"),
    Builtin("SocketReceive", "proc", (_S,), _receive,
            (Opt("Str", ("string",), after=1, group="what", var=True),
             Opt("RawData", ("rawbytes",), after=1, group="what", var=True),
             Opt("Data", ("byte",), after=1, group="what", var=True),
             Opt("ReadNoOfBytes", ("num",), after=1),
             Opt("NoRecBytes", ("num",), after=1, var=True),
             Opt("Time", ("num",), after=1)), need_one=("what",),
            page="Instructions: SocketReceive"),
    Builtin("SocketClose", "proc", (Arg("Socket", ("socketdev",), True),), _close,
            page="Instructions: SocketClose"),
    Builtin("SocketGetStatus", "func", (_S,), _status, ret="socketstatus",
            page="Functions: SocketGetStatus"),
]  # fmt: skip
