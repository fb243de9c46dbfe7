"""rawbytes built-ins: PackRawBytes, UnpackRawBytes, ClearRawBytes, CopyRawBytes, RawBytesLen
(RAPID reference manual, "Instructions" and "Functions": each page's arguments and errors)."""

from __future__ import annotations

import struct

from cell.rapid.interp.builtins.base import Arg, Builtin, Opt
from cell.rapid.interp.consts import NUM_INT_MAX, RAWBYTES_MAX
from cell.rapid.interp.errors import RapidRunError
from cell.rapid.interp.rtypes import F32, RawBytes

_FMT = {1: "B", 2: "H", 4: "I", 8: "Q", -1: "b", -2: "h", -4: "i", -8: "q"}


def _inttype(code) -> int:
    k = int(code)
    if k not in _FMT:
        raise RapidRunError("ERR_ARGVALERR", f"\\IntX {float(code):g} is not an inttypes value")
    return k


def _range(k: int) -> tuple[int, int]:
    bits = 8 * abs(k)
    return (0, 2**bits - 1) if k > 0 else (-(2 ** (bits - 1)), 2 ** (bits - 1) - 1)


def _num_limit(k: int, is_num: bool, lo: int, hi: int) -> tuple[int, int]:
    if is_num and abs(k) >= 4:
        if abs(k) == 8:
            raise RapidRunError("ERR_ARGVALERR", "LINT/ULINT need a dnum value")
        return max(lo, -NUM_INT_MAX + 1), min(hi, NUM_INT_MAX)
    return lo, hi


def _start(raw: RawBytes, index, size: int) -> int:
    i = int(index)
    if i != index or not i >= 1 or i + size - 1 > RAWBYTES_MAX:
        raise RapidRunError("ERR_OUTOFBND", f"StartIndex {float(index):g} (+{size} bytes) "
                            f"outside 1..{RAWBYTES_MAX}")  # fmt: skip
    return i - 1


def pack(
    st, line, value, ref, index, network=False, hex1=False, intx=None, float4=False, ascii=False
):
    c, k = ref
    raw: RawBytes = c[k]
    if intx == 1 and isinstance(value, F32):
        i = int(index)
        if 0 <= value <= 255 and value == int(value) and i == index and 1 <= i <= RAWBYTES_MAX:
            raw.data[i - 1] = int(value)
            raw.n = max(raw.n, i)
            return
    end = "<" if not network else ">"
    if intx is not None:
        if not isinstance(value, F32 | float):
            raise RapidRunError("ERR_ARGVALERR", "\\IntX packs a num or dnum", line)
        code = _inttype(intx)
        lo, hi = _num_limit(code, isinstance(value, F32), *_range(code))
        v = float(value)
        if v != int(v) or not lo <= v <= hi:
            kind = "num" if isinstance(value, F32) else "dnum"
            raise RapidRunError("ERR_ARGVALERR", f"{v:.17g} is not an integer in {lo}..{hi} "
                                f"({kind})", line)  # fmt: skip
        data = struct.pack(end + _FMT[code], int(v))
    elif float4:
        if not isinstance(value, F32 | float):
            raise RapidRunError("ERR_ARGVALERR", "\\Float4 packs a num", line)
        data = struct.pack(end + "f", float(value))
    elif ascii:
        if isinstance(value, str):
            data = value.encode("latin-1")
        elif isinstance(value, int) and not isinstance(value, bool):
            data = bytes([value])
        else:
            raise RapidRunError("ERR_ARGVALERR", "\\ASCII packs a string or a byte", line)
    else:
        if not isinstance(value, int) or isinstance(value, bool):
            raise RapidRunError("ERR_ARGVALERR", "\\Hex1 packs a byte", line)
        data = bytes([value])
    i = _start(raw, index, len(data))
    raw.data[i : i + len(data)] = data
    raw.n = max(raw.n, i + len(data))


def unpack(
    st,
    line,
    raw: RawBytes,
    index,
    ref,
    network=False,
    hex1=False,
    intx=None,
    float4=False,
    ascii=None,
):
    c, k = ref
    old = c[k]
    if intx == 1 and isinstance(old, F32):
        i = int(index)
        if i != index or not 1 <= i <= raw.n:
            _valid(raw, index, 1, line)
        c[k] = F32(raw.data[i - 1])
        return
    end = "<" if not network else ">"
    if intx is not None:
        code = _inttype(intx)
        size = abs(code)
        i = _valid(raw, index, size, line)
        (v,) = struct.unpack(end + _FMT[code], bytes(raw.data[i : i + size]))
        if isinstance(old, F32):
            lo, hi = _num_limit(code, True, *_range(code))
            if not lo <= v <= hi:
                raise RapidRunError("ERR_ARGVALERR", f"{v} does not fit a num exactly", line)
            c[k] = F32(v)
        elif isinstance(old, float):
            c[k] = float(v)
        else:
            raise RapidRunError("ERR_ARGVALERR", "\\IntX unpacks into a num or dnum", line)
    elif float4:
        i = _valid(raw, index, 4, line)
        (v,) = struct.unpack(end + "f", bytes(raw.data[i : i + 4]))
        c[k] = F32(v) if isinstance(old, F32) else float(v)
    elif ascii is not None:
        n = int(ascii)
        i = _valid(raw, index, n, line)
        c[k] = bytes(raw.data[i : i + n]).decode("latin-1")
    else:
        i = _valid(raw, index, 1, line)
        c[k] = int(raw.data[i])


def _valid(raw: RawBytes, index, size: int, line: int) -> int:
    i = int(index)
    if i != index or i < 1 or i + size - 1 > raw.n:
        raise RapidRunError("ERR_OUTOFBND", f"bytes {float(index):g}..{float(index) + size - 1:g}"
                            f" beyond the {raw.n} valid bytes", line)  # fmt: skip
    return i - 1


def clear(st, line, ref, fromindex=None):
    c, k = ref
    raw: RawBytes = c[k]
    start = 0 if fromindex is None else _start(raw, fromindex, 0)
    if raw.n > start:
        raw.data[start : raw.n] = bytes(raw.n - start)
        raw.n = start


def copy(st, line, src: RawBytes, from_index, ref, to_index, noofbytes=None):
    c, k = ref
    dst: RawBytes = c[k]
    f = int(from_index)
    n = src.n - f + 1 if noofbytes is None else int(noofbytes)
    if f < 1 or n < 0 or f + n - 1 > src.n:
        raise RapidRunError("ERR_OUTOFBND", f"{n} bytes from {f} of {src.n} valid", line)
    t = _start(dst, to_index, n)
    dst.data[t : t + n] = src.data[f - 1 : f - 1 + n]
    dst.n = max(dst.n, t + n)


def length(st, line, raw: RawBytes):
    return F32(raw.n)


_PACK_OPTS = (Opt("Network", after=2), Opt("Hex1", after=3, group="fmt"),
              Opt("IntX", ("inttypes",), after=3, group="fmt"),
              Opt("Float4", after=3, group="fmt"), Opt("ASCII", after=3, group="fmt"))  # fmt: skip
_UNPACK_OPTS = (Opt("Network", after=1), Opt("Hex1", after=3, group="fmt"),
                Opt("IntX", ("inttypes",), after=3, group="fmt"),
                Opt("Float4", after=3, group="fmt"),
                Opt("ASCII", ("num",), after=3, group="fmt"))  # fmt: skip
BUILTINS = [
    Builtin("PackRawBytes", "proc",
            (Arg("Value", ("num", "dnum", "byte", "string")), Arg("RawData", ("rawbytes",), True),
             Arg("StartIndex", ("num",))), pack, _PACK_OPTS, need_one=("fmt",),
            page="Instructions: PackRawBytes"),
    Builtin("UnpackRawBytes", "proc",
            (Arg("RawData", ("rawbytes",)), Arg("StartIndex", ("num",)),
             Arg("Value", ("num", "dnum", "byte", "string"), True)), unpack, _UNPACK_OPTS,
            need_one=("fmt",), page="Instructions: UnpackRawBytes"),
    Builtin("ClearRawBytes", "proc", (Arg("RawData", ("rawbytes",), True),), clear,
            (Opt("FromIndex", ("num",), after=1),), page="Instructions: ClearRawBytes"),
    Builtin("CopyRawBytes", "proc",
            (Arg("FromRawData", ("rawbytes",)), Arg("FromIndex", ("num",)),
             Arg("ToRawData", ("rawbytes",), True), Arg("ToIndex", ("num",))), copy,
            (Opt("NoOfBytes", ("num",), after=4),), page="Instructions: CopyRawBytes"),
    Builtin("RawBytesLen", "func", (Arg("RawData", ("rawbytes",)),), length, ret="num",
            page="Functions: RawBytesLen"),
]  # fmt: skip
