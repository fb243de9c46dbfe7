"""A loaded RAPID module: parsed, every name and type checked, its routines compiled; run a
PROC with :meth:`Program.run` against a host (:mod:`cell.rapid.interp.host`).

``consts`` replaces the value of named CONSTs before loading, as an integrator edits the
module's settings (the port, the robot model, the link timeout, the transport)."""

from __future__ import annotations

from pathlib import Path

from cell.rapid.interp.builtins import REGISTRY
from cell.rapid.interp.consts import ERRNOS, INTTYPES, SOCKET_STATES
from cell.rapid.interp.cstmt import Propagate, StmtCompiler
from cell.rapid.interp.errors import RapidLoadError, RapidRunError, RapidStopped
from cell.rapid.interp.parser import parse
from cell.rapid.interp.rtypes import (
    F32,
    Array,
    Record,
    Type,
    base,
    copy_value,
    default,
    default_array,
    known_type,
)
from cell.rapid.interp.scope import Param, Routine, Scope, State


def _predefined(scope: Scope) -> None:
    for name, v in {**ERRNOS, **INTTYPES, **SOCKET_STATES}.items():
        scope.declare(name, Type("num"), "const", 0, F32(v))
    scope.declare("v1000", Type("speeddata"), "const", 0,
                  Record("speeddata", {"v_tcp": F32(1000), "v_ori": F32(500),
                                       "v_leax": F32(5000), "v_reax": F32(1000)}))  # fmt: skip
    # fine := [TRUE, 0, 0, 0, 0, 0, 0]; z5 := [FALSE, 5, 8, 8, 0.8, 8, 0.8] (zonedata)
    for name, values in (("fine", (0, 0, 0, 0, 0, 0)), ("z5", (5, 8, 8, 0.8, 8, 0.8))):
        zone = default("zonedata")
        fields = ("pzone_tcp", "pzone_ori", "pzone_eoffs", "zone_ori", "zone_leax", "zone_reax")
        zone.f.update({f: F32(v) for f, v in zip(fields, values, strict=True)})
        zone.f["finep"] = name == "fine"
        scope.declare(name, Type("zonedata"), "const", 0, zone)
    scope.declare("tool0", Type("tooldata"), "pers", 0)


class Program:
    """One module, ready to run. ``source`` names it in error messages."""

    def __init__(self, text: str, source: str = "<module>", consts: dict | None = None) -> None:
        self.state = State(source=source)
        self.tree = parse(text, source)
        self.scope = Scope(self.state)
        self.routines: dict[str, Routine] = {}
        self._overrides = {k.lower(): v for k, v in (consts or {}).items()}
        _predefined(self.scope)
        self.state.globals[self.scope.lookup("tool0").slot] = _tool0()
        self.name = str(self.tree.children[0])
        self._load()
        unused = set(self._overrides) - {
            k for k, s in self.scope.names.items() if s.kind == "const"
        }
        if unused:
            raise RapidLoadError(f"no CONST {', '.join(sorted(unused))} to set", 0, source)

    @classmethod
    def from_file(cls, path: Path, consts: dict | None = None) -> Program:
        return cls(Path(path).read_text(), str(path), consts)

    # --- loading ----------------------------------------------------------------------------
    def _load(self) -> None:
        items = [c for c in self.tree.children[1:] if hasattr(c, "data")]
        decls = [c for c in items if c.data == "data_decl"]
        routines = [c for c in items if c.data == "routine"]
        module_c = StmtCompiler(self.scope, self.routines, REGISTRY, None)
        for d in decls:
            self._declare(module_c, d, self.scope, True)
        for r in routines:
            self._signature(r.children[-1])
        for r in self.routines.values():
            self._compile(r)

    def _declare(self, c: StmtCompiler, node, scope: Scope, module: bool):
        kids = [k for k in node.children if str(getattr(k, "type", "")) != "LOCAL"]
        storage, tname, name, *rest = kids
        kind = str(storage).lower()
        if not known_type(str(tname)):
            raise c.err(f"unknown data type {tname}", tname)
        dims_node = next((x for x in rest if getattr(x, "data", None) == "dims"), None)
        init = next((x for x in rest if getattr(x, "data", None) != "dims"), None)
        dims = ()
        if dims_node is not None:
            dims = tuple(self._const_int(c, e) for e in dims_node.children)
        t = Type(base(str(tname)), len(dims))
        if kind == "const" and init is None:
            raise c.err(f"CONST {name} needs a value", name)
        if module and kind == "const" and str(name).lower() in self._overrides:
            value = self._override(c, t, str(name))
        elif init is not None:
            value = self._const_value(c, init, t) if module or kind == "const" else None
        else:
            value = default_array(t.name, dims) if dims else default(t.name)
            if not dims and hasattr(value, "name"):
                value.name = str(name).lower()
        sym = scope.declare(str(name), t, kind, node.meta.line, value if kind == "const" else None)
        if module:
            if kind != "const":
                self.state.globals[sym.slot] = value
            return sym, None
        if kind == "const":
            return sym, None
        if init is not None:
            f = c.expr(init, t).fn
            return sym, (lambda: copy_value(f(None)))
        tn, nm = t.name, str(name).lower()
        if dims:
            return sym, (lambda: default_array(tn, dims))
        return sym, (lambda: _named(default(tn), nm))

    def _override(self, c, t: Type, name: str):
        v = self._overrides[name.lower()]
        b = base(t.name)
        if b == "string" and isinstance(v, str):
            return v
        if b in ("num", "dnum") and isinstance(v, int | float) and not isinstance(v, bool):
            return F32(v) if b == "num" else float(v)
        if b == "bool" and isinstance(v, bool):
            return v
        raise RapidLoadError(f"CONST {name} is {t}, cannot be set to {v!r}", 0, self.state.source)

    def _const_value(self, c: StmtCompiler, node, t: Type):
        try:
            return copy_value(c.expr(node, t).fn(None))
        except (TypeError, RapidRunError) as exc:
            raise c.err(f"the value must be known when the module loads ({exc})", node) from None

    def _const_int(self, c: StmtCompiler, node) -> int:
        v = self._const_value(c, node, Type("num"))
        if v != int(v) or v < 1:
            raise c.err(f"array dimension {float(v):g} is not a positive integer", node)
        return int(v)

    def _signature(self, node) -> None:
        kind = node.data
        kids = list(node.children)
        ret = None
        if kind == "func":
            ret = Type(base(str(kids.pop(0))))
        name = kids[0]
        if str(name).lower() in self.routines:
            raise RapidLoadError(
                f"routine {name} declared twice", node.meta.line, self.state.source
            )
        scope = Scope(self.state, self.scope)
        params = []
        pnode = next((k for k in kids if getattr(k, "data", None) == "params"), None)
        for p in pnode.children if pnode is not None else []:
            toks = [str(t) for t in p.children if not hasattr(t, "data")]
            optional = toks[0] == "\\"
            toks = toks[1:] if optional else toks
            access = toks[0].lower() if toks[0].lower() in ("var", "pers", "inout") else "in"
            tname, pname = toks[-2], toks[-1]
            if not known_type(tname):
                raise RapidLoadError(f"unknown data type {tname}", p.meta.line, self.state.source)
            if optional or any(getattr(x, "data", None) == "param_dims" for x in p.children):
                raise RapidLoadError(f"parameter {pname}: optional and array parameters are not "
                                     "supported by this interpreter", p.meta.line,
                                     self.state.source)  # fmt: skip
            sym = scope.declare(pname, Type(base(tname)), "param" if access == "in" else "ref",
                                p.meta.line)  # fmt: skip
            params.append(Param(pname, sym.type, access, optional, sym.slot))
        r = Routine(str(name), kind, ret, params, node.meta.line, node, scope)
        self.routines[str(name).lower()] = r

    def _compile(self, r: Routine) -> None:
        c = StmtCompiler(r.scope, self.routines, REGISTRY, r)
        body = next(k for k in r.tree.children if getattr(k, "data", None) == "body")
        handler = next((k for k in r.tree.children if getattr(k, "data", None) == "handler"), None)
        decls = [k for k in body.children if getattr(k, "data", None) == "data_decl"]
        stmts = [k for k in body.children if getattr(k, "data", None) != "data_decl"]
        for d in decls:
            sym, init = self._declare(c, d, r.scope, False)
            if init is not None:
                r.locals_init.append((sym.slot, init))
        if handler is not None:
            c.compile_handler(handler.children)
        r.run = c.block(stmts)

    # --- running ----------------------------------------------------------------------------
    def global_value(self, name: str):
        """The current value of a module datum (for the host and tests)."""
        sym = self.scope.lookup(name)
        if sym is None:
            raise KeyError(name)
        return sym.value if sym.kind == "const" else self.state.globals[sym.slot]

    def run(self, proc: str, host) -> None:
        """Run PROC ``proc`` (no arguments) to its end; RapidStopped when an error stops it."""
        r = self.routines.get(proc.lower())
        if r is None or r.kind != "proc" or r.params:
            raise RapidLoadError(f"no PROC {proc}() in {self.name}", 0, self.state.source)
        self.state.host = host
        fr = [None] * r.scope.n_slots
        for slot, init in r.locals_init:
            fr[slot] = init()
        try:
            r.run(fr)
        except Propagate as p:
            raise self._stopped(p.err) from None
        except RapidRunError as e:
            raise self._stopped(e) from None

    def call(self, name: str, *args, host=None):
        """Call FUNC or PROC ``name`` with Python values (num as float32, dnum as float; a VAR
        argument's object, e.g. a RawBytes, is passed by reference); the FUNC's value."""
        r = self.routines.get(name.lower())
        if r is None or len(args) != len(r.params):
            raise RapidLoadError(f"no routine {name} with {len(args)} arguments", 0,
                                 self.state.source)  # fmt: skip
        self.state.host = host
        fr = [None] * r.scope.n_slots
        for p, a in zip(r.params, args, strict=True):
            if p.access != "in":
                fr[p.slot] = ([a], 0)
            else:
                fr[p.slot] = {"num": F32, "dnum": float}.get(base(p.type.name), copy_value)(a)
        for slot, init in r.locals_init:
            fr[slot] = init()
        try:
            res = r.run(fr)
        except Propagate as p:
            raise self._stopped(p.err) from None
        except RapidRunError as e:
            raise self._stopped(e) from None
        return None if res is None else res.value

    def _stopped(self, e: RapidRunError) -> RapidStopped:
        return RapidStopped(f"execution stopped: {e.text}", e.line, self.state.source)


def _named(v, name: str):
    if hasattr(v, "name") and not isinstance(v, Array | Record):
        v.name = name
    return v


def _tool0() -> Record:
    t = default("tooldata")
    t.f["robhold"] = True
    return t
