"""How a built-in is declared and bound: its required arguments (type, VAR or in), its
optional arguments and switches (``\\Name``, where they may stand, which exclude each other,
which group needs one), each refused at load time with the line when wrong."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from functools import partial

from cell.rapid.interp.cexpr import Expr, line_of
from cell.rapid.interp.rtypes import Type, assignable, base


@dataclass(frozen=True)
class Arg:
    """A required argument: ``types`` allowed ("anytype": any), ``var``: must be a variable."""

    name: str
    types: tuple[str, ...]
    var: bool = False


@dataclass(frozen=True)
class Opt:
    """An optional argument: ``types`` () for a switch; ``after``: how many required arguments
    precede it; ``group``: optional arguments of one group exclude each other."""

    name: str
    types: tuple[str, ...] = ()
    after: int = 0
    group: str = ""
    var: bool = False


@dataclass
class Builtin:
    """A RAPID instruction (``kind`` proc) or function (func), after its manual page ``page``.

    ``impl(state, line, *required, **optional)`` runs it; VAR arguments arrive as
    (container, key) references. ``ret`` is the function's type ("same": its first argument's).
    ``need_one``: groups of which one member must be given."""

    name: str
    kind: str
    args: tuple[Arg, ...]
    impl: Callable
    opts: tuple[Opt, ...] = ()
    ret: str | None = None
    need_one: tuple[str, ...] = ()
    page: str = ""
    opt_index: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.opt_index = {o.name.lower(): o for o in self.opts}

    def bind(self, c, args, node) -> Expr:
        """Check the call's arguments in compiler ``c``; the call as an expression."""
        pos, opts, n_req, after = [], {}, 0, {}
        for a in args:
            if getattr(a, "data", None) == "opt_arg":
                opts_name = str(a.children[0])
                o = self.opt_index.get(opts_name.lower())
                if o is None:
                    raise c.err(f"{self.name} has no optional argument \\{opts_name}", a)
                if o.name.lower() in opts:
                    raise c.err(f"\\{o.name} given twice to {self.name}", a)
                after[o.name.lower()] = n_req
                opts[o.name.lower()] = (o, a.children[1] if len(a.children) > 1 else None, a)
            else:
                pos.append(a)
                n_req += 1
        if len(pos) != len(self.args):
            names = ", ".join(x.name for x in self.args)
            raise c.err(f"{self.name} takes {len(self.args)} arguments ({names}), "
                        f"{len(pos)} given", node)  # fmt: skip
        for key, (o, _, a) in opts.items():
            if o.after != after[key]:
                raise c.err(f"\\{o.name} of {self.name} must follow argument {o.after} "
                            f"(found after {after[key]})", a)  # fmt: skip
        groups: dict[str, str] = {}
        for o, _, a in opts.values():
            if o.group and o.group in groups:
                raise c.err(f"\\{o.name} and \\{groups[o.group]} of {self.name} exclude each "
                            "other", a)  # fmt: skip
            if o.group:
                groups[o.group] = o.name
        for g in self.need_one:
            if g not in groups:
                alts = " | ".join("\\" + o.name for o in self.opts if o.group == g)
                raise c.err(f"{self.name} needs one of {alts}", node)
        req = [_compile(c, self.name, spec, a) for spec, a in zip(self.args, pos, strict=True)]
        optf = {}
        for key, (o, value, a) in opts.items():
            if not o.types:
                if value is not None:
                    raise c.err(f"\\{o.name} of {self.name} is a switch and takes no value", a)
                optf[key] = None
                continue
            if value is None:
                raise c.err(f"\\{o.name} of {self.name} needs a value (\\{o.name}:=...)", a)
            optf[key] = _compile(c, self.name, Arg(o.name, o.types, o.var), value).fn
        ret = self.ret
        rtype = req[0].type if ret == "same" else Type(ret or "none")
        return Expr(self._closure(c.state, line_of(node), [e.fn for e in req], optf), rtype)

    def _closure(self, st, line: int, req: list, optf: dict):
        static = {k: (True if f is None else f._const) for k, f in optf.items()
                  if f is None or hasattr(f, "_const")}  # fmt: skip
        valued = [(k, f) for k, f in optf.items() if k not in static]
        impl = partial(self.impl, st, line, **static)
        if not valued:
            if len(req) == 0:
                return lambda fr: impl()
            if len(req) == 1:
                (a,) = req
                return lambda fr: impl(a(fr))
            if len(req) == 2:
                a, b = req
                return lambda fr: impl(a(fr), b(fr))
            if len(req) == 3:
                a, b, c = req
                return lambda fr: impl(a(fr), b(fr), c(fr))
            return lambda fr: impl(*[f(fr) for f in req])

        def call(fr):
            kw = {k: f(fr) for k, f in valued}
            return impl(*[f(fr) for f in req], **kw)

        return call


def _compile(c, who: str, spec: Arg, node) -> Expr:
    if spec.var:
        if getattr(node, "data", None) != "ref":
            raise c.err(f"argument {spec.name} of {who} must be a variable", node)
        loc, t, _ = c.location(node)
        if "anytype" not in spec.types and base(t.name) not in {base(x) for x in spec.types}:
            raise c.err(f"type mismatch: {t} for {spec.name} ({'|'.join(spec.types)}) of {who}",
                        node)  # fmt: skip
        return Expr(loc, t)
    e = c.expr(node)
    if "anytype" in spec.types:
        return e
    for tname in spec.types:
        want = Type(tname)
        if e.lit is not None or (base(e.type.name) == base(tname) and not e.type.ndim):
            return c.coerce(e, want, node)
    for tname in spec.types:
        if assignable(Type(tname), e.type):
            return c.coerce(e, Type(tname), node)
    raise c.err(f"type mismatch: {e.type} for {spec.name} ({'|'.join(spec.types)}) of {who}", node)
