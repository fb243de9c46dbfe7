"""Arithmetic, conversion and bit built-ins: Abs, Round, Trunc, Max, Min, Sqrt, NumToDnum,
DnumToNum, BitAndDnum, BitOrDnum, BitXOrDnum, BitRShDnum, BitLShDnum, NumToStr, StrLen (RAPID
reference manual, "Functions"). num results are single precision, dnum results double."""

from __future__ import annotations

import math

from cell.rapid.interp.builtins.base import Arg, Builtin, Opt
from cell.rapid.interp.consts import NUM_INT_MAX
from cell.rapid.interp.errors import RapidRunError
from cell.rapid.interp.rtypes import F32

_U32 = 4294967295
_N = ("num", "dnum")


def _same(x, v):
    return F32(v) if isinstance(x, F32) else float(v)


def _abs(st, line, x):
    return abs(x)


def _round(st, line, x, dec=None):
    d = 0 if dec is None else int(dec)
    if d != (0 if dec is None else dec) or not 0 <= d <= 6 + 9 * isinstance(x, float):
        raise RapidRunError("ERR_ARGVALERR", f"\\Dec {float(dec):g}", line)
    s = 10.0**d
    v = float(x)
    r = math.copysign(math.floor(abs(v) * s + 0.5), v) / s
    return _same(x, r)


def _trunc(st, line, x, dec=None):
    s = 10.0 ** (0 if dec is None else int(dec))
    return _same(x, math.trunc(float(x) * s) / s)


def _max(st, line, a, b):
    return a if a >= b else b


def _min(st, line, a, b):
    return a if a <= b else b


def _sqrt(st, line, x):
    if x < 0:
        raise RapidRunError("ERR_ARGVALERR", f"Sqrt of {float(x):g}", line)
    return _same(x, math.sqrt(float(x)))


def _num_to_dnum(st, line, x):
    return float(x)


def _dnum_to_num(st, line, x, integer=False):
    if integer and (x != int(x) or not -NUM_INT_MAX < x <= NUM_INT_MAX):
        raise RapidRunError("ERR_ARGVALERR", f"{x:.17g} is not an integer of num's range", line)
    if abs(x) > 3.4028234663852886e38:
        raise RapidRunError("ERR_NUMOVERFLOW", f"{x:.17g} beyond num's range", line)
    return F32(x)


def _u32(x, line: int) -> int:
    if x != int(x) or not 0 <= x <= _U32:
        raise RapidRunError("ERR_ARGVALERR", f"{x:.17g} is not an integer in 0..{_U32}", line)
    return int(x)


def _steps(n, line: int) -> int:
    k = int(n)
    if k != n or not 1 <= k <= 32:
        raise RapidRunError("ERR_ARGVALERR", f"ShiftSteps {float(n):g} outside 1..32", line)
    return k


def _band(st, line, a, b):
    ia, ib = int(a), int(b)
    if ia != a or ib != b or not (0 <= ia <= _U32 and 0 <= ib <= _U32):
        _u32(a, line), _u32(b, line)
    return float(ia & ib)


def _bor(st, line, a, b):
    return float(_u32(a, line) | _u32(b, line))


def _bxor(st, line, a, b):
    ia, ib = int(a), int(b)
    if ia != a or ib != b or not (0 <= ia <= _U32 and 0 <= ib <= _U32):
        _u32(a, line), _u32(b, line)
    return float(ia ^ ib)


def _brsh(st, line, a, n):
    ia, k = int(a), int(n)
    if ia != a or not 0 <= ia <= _U32 or k != n or not 1 <= k <= 32:
        _u32(a, line), _steps(n, line)
    return float(ia >> k)


def _blsh(st, line, a, n):
    return float((_u32(a, line) << _steps(n, line)) & _U32)


def _num_to_str(st, line, x, dec, exp=False):
    d = int(dec)
    if d != dec or not 0 <= d <= 15:
        raise RapidRunError("ERR_ARGVALERR", f"Dec {float(dec):g}", line)
    v = float(_round(st, line, float(x), float(d)))
    return f"{v:.{d}e}" if exp else f"{v:.{d}f}"


def _strlen(st, line, s):
    return F32(len(s))


def _d(name, fn):
    return Builtin(name, "func", (Arg("Value1", ("dnum",)), Arg("Value2", ("dnum",))), fn,
                   ret="dnum", page=f"Functions: {name}")  # fmt: skip


BUILTINS = [
    Builtin("Abs", "func", (Arg("Value", _N),), _abs, ret="same", page="Functions: Abs"),
    Builtin("Round", "func", (Arg("Val", _N),), _round, (Opt("Dec", ("num",), after=1),),
            ret="same", page="Functions: Round"),
    Builtin("Trunc", "func", (Arg("Val", _N),), _trunc, (Opt("Dec", ("num",), after=1),),
            ret="same", page="Functions: Trunc"),
    Builtin("Max", "func", (Arg("Value1", _N), Arg("Value2", _N)), _max, ret="same",
            page="Functions: Max"),
    Builtin("Min", "func", (Arg("Value1", _N), Arg("Value2", _N)), _min, ret="same",
            page="Functions: Min"),
    Builtin("Sqrt", "func", (Arg("Value", _N),), _sqrt, ret="same", page="Functions: Sqrt"),
    Builtin("NumToDnum", "func", (Arg("Value", ("num",)),), _num_to_dnum, ret="dnum",
            page="Functions: NumToDnum"),
    Builtin("DnumToNum", "func", (Arg("Value", ("dnum",)),), _dnum_to_num,
            (Opt("Integer", after=1),), ret="num", page="Functions: DnumToNum"),
    _d("BitAndDnum", _band), _d("BitOrDnum", _bor), _d("BitXOrDnum", _bxor),
    Builtin("BitRShDnum", "func", (Arg("Value", ("dnum",)), Arg("ShiftSteps", ("num",))), _brsh,
            ret="dnum", page="Functions: BitRShDnum"),
    Builtin("BitLShDnum", "func", (Arg("Value", ("dnum",)), Arg("ShiftSteps", ("num",))), _blsh,
            ret="dnum", page="Functions: BitLShDnum"),
    Builtin("NumToStr", "func", (Arg("Val", _N), Arg("Dec", ("num",))), _num_to_str,
            (Opt("Exp", after=2),), ret="string", page="Functions: NumToStr"),
    Builtin("StrLen", "func", (Arg("Str", ("string",)),), _strlen, ret="num",
            page="Functions: StrLen"),
]  # fmt: skip
