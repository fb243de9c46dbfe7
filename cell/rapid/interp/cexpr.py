"""Expressions compiled to closures ``fn(frame) -> value`` with their static type: operators
with RAPID's typing (num in single precision, dnum in double, mixed num/dnum as dnum), data
references (arrays, record fields), aggregates and function calls."""

from __future__ import annotations

import numpy as np
from lark import Token, Tree

from cell.rapid.interp.errors import RapidLoadError, RapidRunError
from cell.rapid.interp.rtypes import (
    F32,
    RECORDS,
    Array,
    Record,
    Type,
    assignable,
    base,
    check_string,
    converter,
    copy_value,
)
from cell.rapid.interp.scope import Scope

NUM, DNUM, BOOL, STRING = Type("num"), Type("dnum"), Type("bool"), Type("string")


class Expr:
    """A compiled expression: ``fn(frame)``, its type, and the exact value of a numeric literal
    (which is num or dnum as its context needs)."""

    __slots__ = ("fn", "lit", "type")

    def __init__(self, fn, type_: Type, lit: float | None = None) -> None:
        self.fn, self.type, self.lit = fn, type_, lit


def constant(v):
    """A closure returning ``v``, marked (``_const``) so callers may fold it."""

    def fn(fr):
        return v

    fn._const = v
    return fn


def line_of(node) -> int:
    if isinstance(node, Token):
        return node.line or 0
    return getattr(node.meta, "line", 0) if hasattr(node, "meta") else 0


class ExprCompiler:
    """Compiles expressions within ``self.scope``; subclassed by the statement compiler."""

    def __init__(self, scope: Scope, routines: dict, builtins: dict) -> None:
        self.scope, self.routines, self.builtins = scope, routines, builtins
        self.state = scope.state

    def err(self, text: str, node) -> RapidLoadError:
        return RapidLoadError(text, line_of(node), self.state.source)

    # --- entry ------------------------------------------------------------------------------
    def expr(self, node, want: Type | None = None) -> Expr:
        """Compile ``node``; with ``want``, converted to that type (or refused)."""
        e = self._expr(node, want)
        return self.coerce(e, want, node) if want is not None else e

    def coerce(self, e: Expr, want: Type, node) -> Expr:
        if e.lit is not None and base(want.name) in ("num", "dnum") and not want.ndim:
            v = F32(e.lit) if base(want.name) == "num" else float(e.lit)
            return Expr(constant(v), want)
        if not assignable(want, e.type):
            raise self.err(f"type mismatch: {e.type} where {want} is expected", node)
        conv = converter(want, e.type)
        if conv is None:
            return e
        fn = e.fn
        return Expr(lambda fr: conv(fn(fr)), want)

    def _expr(self, node, want: Type | None) -> Expr:
        if isinstance(node, Token):
            raise self.err(f"unexpected {node!s}", node)
        k = node.data
        if k == "num_lit":
            v = float(node.children[0])
            return Expr(constant(F32(v)), NUM, v)
        if k == "str_lit":
            s = _string_literal(str(node.children[0]))
            if len(s) > 80:
                raise self.err("string literal longer than 80 characters", node)
            return Expr(lambda fr: s, STRING)
        if k in ("true_lit", "false_lit"):
            b = k == "true_lit"
            return Expr(lambda fr: b, BOOL)
        if k == "ref":
            return self.ref(node)
        if k == "fcall":
            return self.fcall(node)
        if k == "aggregate":
            return self.aggregate(node, want)
        if k == "neg_op":
            return self._neg(node)
        if k == "not_op":
            a = self.expr(node.children[0], BOOL).fn
            return Expr(lambda fr: not a(fr), BOOL)
        if k in ("and_op", "or_op", "xor_op"):
            a = self.expr(node.children[0], BOOL).fn
            b = self.expr(node.children[1], BOOL).fn
            f = {"and_op": lambda fr: bool(a(fr)) & bool(b(fr)),
                 "or_op": lambda fr: bool(a(fr)) | bool(b(fr)),
                 "xor_op": lambda fr: bool(a(fr)) ^ bool(b(fr))}[k]  # fmt: skip
            return Expr(f, BOOL)
        if k == "rel_op":
            return self._rel(node)
        if k == "bin_op":
            return self._bin(node)
        raise self.err(f"unsupported expression {k}", node)

    # --- operators --------------------------------------------------------------------------
    def _neg(self, node) -> Expr:
        sign, arg = node.children
        e = self._expr(arg, None)
        if base(e.type.name) not in ("num", "dnum") or e.type.ndim:
            raise self.err(f"unary {sign} on {e.type}", node)
        if e.lit is not None:
            v = -e.lit if str(sign) == "-" else e.lit
            return Expr(constant(F32(v)), NUM, v)
        fn = e.fn
        return Expr((lambda fr: -fn(fr)) if str(sign) == "-" else fn, Type(base(e.type.name)))

    def _numeric_pair(self, node) -> tuple[Expr, Expr, Type]:
        a = self._expr(node.children[0], None)
        b = self._expr(node.children[2], None)
        ta, tb = base(a.type.name), base(b.type.name)
        if (
            a.type.ndim
            or b.type.ndim
            or ta not in ("num", "dnum", "byte")
            or tb not in ("num", "dnum", "byte")
        ):
            return a, b, Type("?")
        if a.lit is not None and b.lit is None:
            t = NUM if tb == "byte" else Type(tb)
        elif b.lit is not None and a.lit is None:
            t = NUM if ta == "byte" else Type(ta)
        else:
            t = DNUM if "dnum" in (ta, tb) else NUM
        return self.coerce(a, t, node), self.coerce(b, t, node), t

    def _rel(self, node) -> Expr:
        op = str(node.children[1])
        a, b, t = self._numeric_pair(node)
        if t.name == "?" and (
            a.type != b.type or base(a.type.name) not in ("bool", "string") or op not in ("=", "<>")
        ):
            raise self.err(f"cannot compare {a.type} {op} {b.type}", node)
        fa, fb = a.fn, b.fn
        f = {"=": lambda fr: bool(fa(fr) == fb(fr)), "<>": lambda fr: bool(fa(fr) != fb(fr)),
             "<": lambda fr: bool(fa(fr) < fb(fr)), ">": lambda fr: bool(fa(fr) > fb(fr)),
             "<=": lambda fr: bool(fa(fr) <= fb(fr)),
             ">=": lambda fr: bool(fa(fr) >= fb(fr))}[op]  # fmt: skip
        return Expr(f, BOOL)

    def _bin(self, node) -> Expr:
        op = str(node.children[1]).upper()
        a, b, t = self._numeric_pair(node)
        line = line_of(node)
        if t.name == "?":
            if op == "+" and a.type == b.type == STRING:
                fa, fb = a.fn, b.fn
                return Expr(lambda fr: check_string(fa(fr) + fb(fr), line), STRING)
            raise self.err(f"operator {op} on {a.type} and {b.type}", node)
        fa, fb = a.fn, b.fn
        if op == "+":
            return Expr(lambda fr: fa(fr) + fb(fr), t)
        if op == "-":
            return Expr(lambda fr: fa(fr) - fb(fr), t)
        if op == "*":
            return Expr(lambda fr: fa(fr) * fb(fr), t)
        if op == "/":

            def div(fr):
                d = fb(fr)
                if d == 0:
                    raise RapidRunError("ERR_DIVZERO", "division by zero", line)
                return fa(fr) / d

            return Expr(div, t)
        cast = F32 if t == NUM else float

        def intop(fr):
            x, y = fa(fr), fb(fr)
            if x != int(x) or y != int(y):
                raise RapidRunError("ERR_ARGVALERR", f"{op} needs integers, got {x} and {y}", line)
            if y == 0:
                raise RapidRunError("ERR_DIVZERO", f"{op} by zero", line)
            q = int(np.trunc(float(x) / float(y))) if op == "DIV" else None
            return cast(q) if q is not None else cast(np.fmod(float(x), float(y)))

        return Expr(intop, t)

    # --- data references --------------------------------------------------------------------
    def symbol(self, name_tok):
        name = str(name_tok)
        sym = self.scope.lookup(name)
        if sym is None:
            if name.upper() == "ERRNO":
                st = self.state
                return None, Expr(lambda fr: F32(st.errno), Type("errnum"))
            raise self.err(f"{name} is not declared", name_tok)
        return sym, None

    def ref(self, node) -> Expr:
        name_tok, *sels = node.children
        sym, special = self.symbol(name_tok)
        if special is not None:
            if sels:
                raise self.err("ERRNO has no components", node)
            return special
        get = self._getter(sym)
        t = sym.type
        for sel in sels:
            get, t = self._select(get, t, sel)
        return Expr(get, t)

    def _getter(self, sym):
        i = sym.slot
        if sym.kind == "const":
            v = sym.value
            return (lambda fr: copy_value(v)) if isinstance(v, Record | Array) else constant(v)
        if sym.is_global:
            g = self.state.globals
            return lambda fr: g[i]
        if sym.kind == "ref":

            def deref(fr):
                c, k = fr[i]
                return c[k]

            return deref
        return lambda fr: fr[i]

    def _select(self, get, t: Type, sel):
        line = line_of(sel)
        if sel.data == "index":
            if not t.ndim:
                raise self.err(f"{t} is not an array", sel)
            idx = [self.expr(c, NUM).fn for c in sel.children]
            if len(idx) != t.ndim:
                raise self.err(f"{len(idx)} indices for an array of {t.ndim} dimensions", sel)

            if len(idx) == 1:
                (f0,) = idx

                def at1(fr):
                    a, i = get(fr), f0(fr)
                    k = int(i)
                    if k != i or not 0 < k <= a.dims[0]:
                        a.offset([i], line)
                    return a.v[k - 1]

                return at1, t.elem

            def at(fr):
                a = get(fr)
                return a.v[a.offset([f(fr) for f in idx], line)]

            return at, t.elem
        fname = str(sel.children[0]).lower()
        ftype = self._field_type(t, fname, sel)
        return (lambda fr: get(fr).f[fname]), ftype

    def _field_type(self, t: Type, fname: str, node) -> Type:
        fields = dict(RECORDS.get(base(t.name), []))
        if t.ndim or fname not in fields:
            raise self.err(f"{t} has no component {fname}", node)
        return Type(fields[fname])

    def location(self, node):
        """An assignable reference: ``loc(frame) -> (container, key)``, its type, its symbol."""
        name_tok, *sels = node.children
        sym, special = self.symbol(name_tok)
        if special is not None or sym.kind in ("const", "for"):
            what = "ERRNO" if special is not None else f"{sym.kind.upper()} {sym.name}"
            raise self.err(f"{what} is read-only", node)
        i = sym.slot
        if sym.is_global:
            g = self.state.globals
            loc = lambda fr: (g, i)  # noqa: E731
        elif sym.kind == "ref":
            loc = lambda fr: fr[i]  # noqa: E731
        else:
            loc = lambda fr: (fr, i)  # noqa: E731
        t = sym.type
        for sel in sels:
            loc, t = self._select_loc(loc, t, sel)
        return loc, t, sym

    def _select_loc(self, loc, t: Type, sel):
        line = line_of(sel)
        if sel.data == "index":
            if not t.ndim:
                raise self.err(f"{t} is not an array", sel)
            idx = [self.expr(c, NUM).fn for c in sel.children]
            if len(idx) != t.ndim:
                raise self.err(f"{len(idx)} indices for an array of {t.ndim} dimensions", sel)
            et = t.elem

            def at(fr):
                c, k = loc(fr)
                a = c[k]
                return a.v, a.offset([f(fr) for f in idx], line)

            return at, et
        fname = str(sel.children[0]).lower()
        ftype = self._field_type(t, fname, sel)

        def fld(fr):
            c, k = loc(fr)
            return c[k].f, fname

        return fld, ftype

    # --- aggregates and calls -----------------------------------------------------------------
    def aggregate(self, node, want: Type | None) -> Expr:
        if want is None or want.ndim or base(want.name) not in RECORDS:
            raise self.err("an aggregate [...] needs a record type from its context", node)
        fields = RECORDS[base(want.name)]
        if len(node.children) != len(fields):
            raise self.err(f"{want} has {len(fields)} components, "
                           f"the aggregate {len(node.children)}", node)  # fmt: skip
        parts = [(f, self.expr(c, Type(ft)).fn) for (f, ft), c in zip(fields, node.children,
                                                                      strict=True)]  # fmt: skip
        rt = base(want.name)
        return Expr(lambda fr: Record(rt, {f: p(fr) for f, p in parts}), want)

    def fcall(self, node) -> Expr:
        name_tok = node.children[0]
        args = node.children[1].children if len(node.children) > 1 else []
        return self.call(name_tok, args, node, function=True)

    def call(self, name_tok, args, node, function: bool):
        """Overridden by the statement compiler (calls of routines and built-ins)."""
        raise self.err(f"unknown {'function' if function else 'instruction'} {name_tok}", node)


def _string_literal(tok: str) -> str:
    body, out, i = tok[1:-1], [], 0
    while i < len(body):
        c = body[i]
        if c == '"' or (c == "\\" and body[i + 1] == "\\"):
            out.append(c)
            i += 2
        elif c == "\\":
            out.append(chr(int(body[i + 1 : i + 3], 16)))
            i += 3
        else:
            out.append(c)
            i += 1
    return "".join(out)


__all__ = ["BOOL", "DNUM", "NUM", "STRING", "Expr", "ExprCompiler", "Tree", "line_of"]
