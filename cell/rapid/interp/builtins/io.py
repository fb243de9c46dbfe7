"""Serial channel built-ins: Open, Close, ClearIOBuff, ReadBin, ReadRawBytes, WriteRawBytes
(RAPID reference manual, "File and serial channel handling"). The device behind
``Open "com1:"`` is the host's; a read that times out raises ERR_DEV_MAXTIME."""

from __future__ import annotations

from time import monotonic

from cell.rapid.interp.builtins.base import Arg, Builtin, Opt
from cell.rapid.interp.errors import RapidRunError
from cell.rapid.interp.rtypes import F32, RawBytes

#: ReadBin / ReadRawBytes wait this long without \Time (RAPID: forever; here a bound)
DEFAULT_TIME_S = 60.0


def _dev(h, line: int):
    if h.obj is None:
        raise RapidRunError("ERR_FILEACC", f"{h.name or 'iodev'} is not open", line)
    return h.obj


def _open(st, line, name, ref, file=None, read=False, write=False, append=False, bin=False):
    c, k = ref
    h = c[k]
    if h.obj is not None:
        raise RapidRunError("ERR_FILEOPEN", f"{h.name} is already open", line)
    h.obj = st.host.open_device(name if file is None else name + file)


def _close(st, line, ref):
    c, k = ref
    h = c[k]
    if h.obj is not None:
        h.obj.close()
        h.obj = None


def _clear(st, line, ref):
    c, k = ref
    _dev(c[k], line).clear_input()


def _read_bin(st, line, h, time=None):
    st.host.poll()
    data = _dev(h, line).read(1, DEFAULT_TIME_S if time is None else float(time))
    if not data:
        raise RapidRunError("ERR_DEV_MAXTIME", "no byte within \\Time", line)
    return F32(data[0])


def _read_raw(st, line, h, ref, n, time=None):
    st.host.poll()
    c, k = ref
    raw: RawBytes = c[k]
    want = int(n)
    if want != n or not 1 <= want <= 1024:
        raise RapidRunError("ERR_ARGVALERR", f"NoOfBytes {float(n):g} outside 1..1024", line)
    dev, out = _dev(h, line), b""
    end = monotonic() + (DEFAULT_TIME_S if time is None else float(time))
    while len(out) < want:
        got = dev.read(want - len(out), max(0.0, end - monotonic()))
        if not got:
            raise RapidRunError("ERR_DEV_MAXTIME", f"{len(out)} of {want} bytes within \\Time",
                                line)  # fmt: skip
        out += got
    raw.data[:want], raw.n = out, want


def _write_raw(st, line, h, raw: RawBytes, noofbytes=None):
    st.host.poll()
    n = raw.n if noofbytes is None else int(noofbytes)
    if not 0 <= n <= raw.n:
        raise RapidRunError("ERR_OUTOFBND", f"NoOfBytes {n} of {raw.n} valid", line)
    _dev(h, line).write(bytes(raw.data[:n]))


BUILTINS = [
    Builtin("Open", "proc", (Arg("Object", ("string",)), Arg("IODevice", ("iodev",), True)),
            _open, (Opt("File", ("string",), after=1), Opt("Read", after=2, group="mode"),
                    Opt("Write", after=2, group="mode"), Opt("Append", after=2, group="mode"),
                    Opt("Bin", after=2)), page="Instructions: Open"),
    Builtin("Close", "proc", (Arg("IODevice", ("iodev",), True),), _close,
            page="Instructions: Close"),
    Builtin("ClearIOBuff", "proc", (Arg("IODevice", ("iodev",), True),), _clear,
            page="Instructions: ClearIOBuff"),
    Builtin("ReadBin", "func", (Arg("IODevice", ("iodev",)),), _read_bin,
            (Opt("Time", ("num",), after=1),), ret="num", page="Functions: ReadBin"),
    Builtin("ReadRawBytes", "proc", (Arg("IODevice", ("iodev",)),
            Arg("RawData", ("rawbytes",), True), Arg("NoOfBytes", ("num",))), _read_raw,
            (Opt("Time", ("num",), after=3),), page="Instructions: ReadRawBytes"),
    Builtin("WriteRawBytes", "proc", (Arg("IODevice", ("iodev",)), Arg("RawData", ("rawbytes",))),
            _write_raw, (Opt("NoOfBytes", ("num",), after=2),),
            page="Instructions: WriteRawBytes"),
]  # fmt: skip
