"""Every built-in instruction and function the interpreter knows, by lower-case name."""

from __future__ import annotations

from cell.rapid.interp.builtins import clock, io, mathbits, motion, rawbytes, sockets
from cell.rapid.interp.builtins.base import Builtin

REGISTRY: dict[str, Builtin] = {
    b.name.lower(): b
    for mod in (clock, io, mathbits, motion, rawbytes, sockets)
    for b in mod.BUILTINS
}
