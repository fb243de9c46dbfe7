"""Names of a module while it is compiled: module data, a routine's parameters and locals,
FOR counters; the run-time state every compiled closure shares (globals, ERRNO, the host)."""

from __future__ import annotations

from dataclasses import dataclass, field

from cell.rapid.interp.errors import RapidLoadError
from cell.rapid.interp.rtypes import Type


@dataclass
class Symbol:
    """A data name: ``kind`` is const, var, pers, param, ref (a VAR/INOUT/PERS parameter, its
    slot holding a (container, key) reference) or for; ``slot`` indexes globals or the frame."""

    name: str
    type: Type
    kind: str
    slot: int
    is_global: bool
    line: int
    value: object = None  # a CONST's value


@dataclass
class State:
    """What the compiled closures share at run time."""

    globals: list = field(default_factory=list)
    errno: int = 0
    host: object = None
    source: str = "<module>"


class Scope:
    """Module names (``parent`` None) or one routine's names on top of them."""

    def __init__(self, state: State, parent: Scope | None = None) -> None:
        self.state, self.parent = state, parent
        self.names: dict[str, Symbol] = {}
        self.n_slots = 0

    def declare(self, name: str, type_: Type, kind: str, line: int, value=None) -> Symbol:
        key = name.lower()
        if key in self.names:
            raise RapidLoadError(f"{name} declared twice (first at line {self.names[key].line})",
                                 line, self.state.source)  # fmt: skip
        is_global = self.parent is None
        if is_global:
            slot = len(self.state.globals)
            self.state.globals.append(None)
        else:
            owner = self.frame_owner()
            slot, owner.n_slots = owner.n_slots, owner.n_slots + 1
        sym = Symbol(name, type_, kind, slot, is_global, line, value)
        self.names[key] = sym
        return sym

    def lookup(self, name: str) -> Symbol | None:
        s: Scope | None = self
        key = name.lower()
        while s is not None:
            if key in s.names:
                return s.names[key]
            s = s.parent
        return None

    def child(self) -> Scope:
        """A nested scope sharing this routine's frame (a FOR counter)."""
        c = Scope(self.state, self)
        c._frame_owner = self.frame_owner()
        return c

    def frame_owner(self) -> Scope:
        return getattr(self, "_frame_owner", self)


@dataclass
class Param:
    """A routine parameter: ``access`` in, var, inout or pers; ``optional`` for \\Name."""

    name: str
    type: Type
    access: str
    optional: bool
    slot: int


@dataclass
class Routine:
    """A PROC or FUNC: its signature and, once compiled, ``run(frame)``."""

    name: str
    kind: str  # proc, func, trap
    ret: Type | None
    params: list[Param]
    line: int
    tree: object = None
    scope: Scope | None = None
    run: object = None
    locals_init: list = field(default_factory=list)
