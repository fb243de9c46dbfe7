"""RAPID data types and values as the controller keeps them.

``num`` is an IEEE single (a ``numpy.float32``: every result is rounded to single precision),
``dnum`` an IEEE double (a Python ``float``), ``bool``, ``string`` (at most 80 characters),
``byte`` (0..255), ``rawbytes`` (up to 1024 bytes with a current length), records
(``jointtarget``, ``robjoint``...) and arrays (1-based, row-major, fixed dimensions). Records and
arrays are copied on assignment, as in RAPID."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cell.rapid.interp.consts import RAWBYTES_MAX, STRING_MAX
from cell.rapid.interp.errors import RapidRunError

F32 = np.float32
#: alias types: stored and checked as their base type
ALIASES = {"errnum": "num", "intnum": "num", "inttypes": "num", "socketstatus": "num"}
NUMERIC = ("num", "dnum")
#: atomic types with no fields and no value arithmetic (objects the built-ins handle)
OBJECT_TYPES = ("iodev", "clock", "signalai", "signaldi", "signaldo", "signalao", "socketdev")

_NUM6 = [(f"rax_{i}", "num") for i in range(1, 7)]
#: record types: field name and type, in order
RECORDS: dict[str, list[tuple[str, str]]] = {
    "robjoint": _NUM6,
    "extjoint": [(f"eax_{c}", "num") for c in "abcdef"],
    "jointtarget": [("robax", "robjoint"), ("extax", "extjoint")],
    "speeddata": [("v_tcp", "num"), ("v_ori", "num"), ("v_leax", "num"), ("v_reax", "num")],
    "zonedata": [("finep", "bool"), ("pzone_tcp", "num"), ("pzone_ori", "num"),
                 ("pzone_eoffs", "num"), ("zone_ori", "num"), ("zone_leax", "num"),
                 ("zone_reax", "num")],
    "tooldata": [("robhold", "bool")],
}  # fmt: skip


@dataclass(frozen=True)
class Type:
    """A static type: a base name and, for arrays, the number of dimensions."""

    name: str
    ndim: int = 0

    def __str__(self) -> str:
        return self.name + ("{" + ",".join("*" * self.ndim) + "}" if self.ndim else "")

    @property
    def elem(self) -> Type:
        return Type(self.name)


def base(name: str) -> str:
    """The stored type of a type name (aliases resolved, lower case)."""
    n = name.lower()
    return ALIASES.get(n, n)


def known_type(name: str) -> bool:
    n = base(name)
    return (
        n in ("num", "dnum", "bool", "string", "byte", "rawbytes")
        or n in RECORDS
        or (n in OBJECT_TYPES)
    )


class Record:
    """A record value: ``type`` and its fields in a dict (copied on assignment)."""

    __slots__ = ("f", "type")

    def __init__(self, type_: str, fields: dict) -> None:
        self.type, self.f = type_, fields

    def copy(self) -> Record:
        return Record(self.type, {k: copy_value(v) for k, v in self.f.items()})


class RawBytes:
    """A ``rawbytes`` container: 1024 bytes and the current length of valid bytes."""

    __slots__ = ("data", "n")

    def __init__(self) -> None:
        self.data, self.n = bytearray(RAWBYTES_MAX), 0

    def copy(self) -> RawBytes:
        r = RawBytes()
        r.data[:], r.n = self.data, self.n
        return r

    def valid(self) -> bytes:
        return bytes(self.data[: self.n])


class Array:
    """An array value: dimensions and the elements, row-major; indices are 1-based."""

    __slots__ = ("dims", "v")

    def __init__(self, dims: tuple[int, ...], values: list) -> None:
        self.dims, self.v = dims, values

    def copy(self) -> Array:
        return Array(self.dims, [copy_value(x) for x in self.v])

    def offset(self, idx: list, line: int) -> int:
        if len(idx) != len(self.dims):
            raise RapidRunError("ERR_OUTOFBND", f"{len(idx)} indices for {len(self.dims)}", line)
        off = 0
        for i, d in zip(idx, self.dims, strict=True):
            k = int(i)
            if k != i or not 1 <= k <= d:
                raise RapidRunError("ERR_OUTOFBND", f"index {float(i):g} outside 1..{d}", line)
            off = off * d + k - 1
        return off


class Handle:
    """The value of an object type (``iodev``, ``clock``, ``socketdev``, ``signalai``): the
    built-ins keep their state in ``obj``."""

    __slots__ = ("name", "obj", "type")

    def __init__(self, type_: str, name: str = "") -> None:
        self.type, self.obj, self.name = type_, None, name

    def copy(self) -> Handle:
        return self


def copy_value(v):
    """A value as assigned: records, rawbytes and arrays copied, the rest as is."""
    return v.copy() if isinstance(v, Record | RawBytes | Array) else v


def default(type_name: str):
    """The value of an uninitialised variable of this (non-array) type."""
    n = base(type_name)
    if n == "num":
        return F32(0.0)
    if n == "dnum":
        return 0.0
    if n == "bool":
        return False
    if n == "string":
        return ""
    if n == "byte":
        return 0
    if n == "rawbytes":
        return RawBytes()
    if n in RECORDS:
        return Record(n, {f: default(t) for f, t in RECORDS[n]})
    return Handle(n)


def default_array(type_name: str, dims: tuple[int, ...]) -> Array:
    count = 1
    for d in dims:
        count *= d
    return Array(dims, [default(type_name) for _ in range(count)])


def check_string(s: str, line: int) -> str:
    if len(s) > STRING_MAX:
        raise RapidRunError("ERR_STRTOOLONG", f"string of {len(s)} characters (max 80)", line)
    return s


def assignable(dst: Type, src: Type) -> bool:
    """Whether a value of type ``src`` may be assigned to (or passed as) ``dst``."""
    if dst.ndim != src.ndim:
        return False
    d, s = base(dst.name), base(src.name)
    if d == s:
        return True
    return {d, s} <= {"num", "dnum", "byte"}


def converter(dst: Type, src: Type):
    """A function turning a value of ``src`` into ``dst`` (None: no conversion needed)."""
    d, s = base(dst.name), base(src.name)
    if d == s or dst.ndim:
        return None
    if d == "num":
        return F32
    if d == "dnum":
        return float
    if d == "byte":
        return _to_byte
    return None


def _to_byte(v) -> int:
    k = int(v)
    if k != v or not 0 <= k <= 255:
        raise RapidRunError("ERR_ARGVALERR", f"{float(v):g} is not a byte (0..255)")
    return k
