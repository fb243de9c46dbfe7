"""Statements and routine calls compiled to closures ``fn(frame) -> None | control``.

A block runs its statements in order; ``RETURN`` comes back as a :class:`Ret`. In a routine
with an ``ERROR`` handler every block catches a run-time error, sets ``ERRNO`` and runs the
handler: ``RETRY`` runs the failed statement again, ``TRYNEXT`` the next one, ``RETURN`` ends
the routine, ``RAISE`` passes the error to the caller."""

from __future__ import annotations

from cell.rapid.interp.cexpr import BOOL, NUM, Expr, ExprCompiler, line_of
from cell.rapid.interp.errors import RapidRunError, RapidStopped
from cell.rapid.interp.rtypes import (
    F32,
    Type,
    assignable,
    base,
    check_string,
    converter,
    copy_value,
)
from cell.rapid.interp.scope import Routine

#: RETRY more often than this on one error stops the program (RobotWare's default)
MAX_RETRIES = 4
RETRY, TRYNEXT = object(), object()


class Ret:
    __slots__ = ("value",)

    def __init__(self, value) -> None:
        self.value = value


class Propagate(Exception):  # noqa: N818 (control flow, not an error)
    """An error leaving a routine's handler for the caller (not caught by the same routine)."""

    def __init__(self, err: RapidRunError) -> None:
        self.err = err


class StmtCompiler(ExprCompiler):
    """Compiles one routine's statements (``routine``) in its scope."""

    def __init__(self, scope, routines, builtins, routine: Routine | None) -> None:
        super().__init__(scope, routines, builtins)
        self.routine = routine
        self.handler = None
        self.in_handler = False

    # --- blocks -----------------------------------------------------------------------------
    def block(self, stmts) -> object:
        items = [(self.stmt(s), line_of(s)) for s in stmts]
        if self.handler is not None and not self.in_handler:
            return self._guarded(items)

        def run(fr):
            for s, line in items:
                try:
                    r = s(fr)
                except RapidRunError as e:
                    e.line = e.line or line
                    raise
                if r is not None:
                    return r
            return None

        return run

    def _guarded(self, items):
        st, holder, n = self.state, self, len(items)

        def run(fr):
            i = retries = 0
            while i < n:
                s, line = items[i]
                try:
                    r = s(fr)
                except RapidRunError as e:
                    e.line = e.line or line
                    st.errno, st.current = e.errno, e
                    try:
                        act = holder.handler(fr)
                    except RapidRunError as e2:
                        raise Propagate(e2) from None
                    if act is RETRY:
                        retries += 1
                        if retries > MAX_RETRIES:
                            raise RapidStopped(f"RETRY limit ({MAX_RETRIES}) after {e}", line,
                                               st.source) from None  # fmt: skip
                        continue
                    if act is TRYNEXT:
                        i += 1
                        continue
                    return act if act is not None else Ret(_NO_VALUE)
                if r is not None:
                    return r
                i += 1
            return None

        return run

    def compile_handler(self, stmts) -> None:
        self.in_handler = True
        body = self.block(stmts)
        self.in_handler = False
        self.handler = body

    # --- statements -------------------------------------------------------------------------
    def stmt(self, node):
        k = node.data
        f = getattr(self, "_s_" + k, None)
        if f is None:
            raise self.err(f"unsupported statement {k}", node)
        return f(node)

    def _s_assign(self, node):
        target, value = node.children
        loc, t, _ = self.location(target)
        v = self.expr(value, t).fn
        if base(t.name) == "string":
            line = line_of(node)

            def assign_s(fr):
                c, k = loc(fr)
                c[k] = check_string(v(fr), line)

            return assign_s

        if base(t.name) in _SCALARS and not t.ndim:

            def assign_v(fr):
                c, k = loc(fr)
                c[k] = v(fr)

            return assign_v

        def assign(fr):
            c, k = loc(fr)
            c[k] = copy_value(v(fr))

        return assign

    def _s_call(self, node):
        args = node.children[1].children if len(node.children) > 1 else []
        e = self.call(node.children[0], args, node, function=False)
        return e.fn

    def _s_if_full(self, node):
        cond, *rest = node.children
        branches = []
        body = [c for c in rest if c.data not in ("elseif", "else_")]
        branches.append((self.expr(cond, BOOL).fn, self.block(body)))
        other = None
        for c in rest:
            if c.data == "elseif":
                branches.append((self.expr(c.children[0], BOOL).fn, self.block(c.children[1:])))
            elif c.data == "else_":
                other = self.block(c.children)

        def run(fr):
            for test, blk in branches:
                if test(fr):
                    return blk(fr)
            return other(fr) if other is not None else None

        return run

    def _s_if_compact(self, node):
        test = self.expr(node.children[0], BOOL).fn
        blk = self.stmt(node.children[1])
        return lambda fr: blk(fr) if test(fr) else None

    def _s_while_(self, node):
        test = self.expr(node.children[0], BOOL).fn
        blk = self.block(node.children[1:])

        def run(fr):
            while test(fr):
                r = blk(fr)
                if r is not None:
                    return r
            return None

        return run

    def _s_for_(self, node):
        name, lo, hi, *rest = node.children
        step = None
        if rest and getattr(rest[0], "data", None) == "step":
            step = self.expr(rest.pop(0).children[0], NUM).fn
        lo_f, hi_f = self.expr(lo, NUM).fn, self.expr(hi, NUM).fn
        outer = self.scope
        self.scope = outer.child()
        sym = self.scope.declare(str(name), NUM, "for", line_of(name))
        blk = self.block(rest)
        self.scope = outer
        i = sym.slot

        def run(fr):
            a, b = lo_f(fr), hi_f(fr)
            d = step(fr) if step is not None else F32(1.0 if b >= a else -1.0)
            k = a
            while (k <= b) if d > 0 else (k >= b):
                fr[i] = k
                r = blk(fr)
                if r is not None:
                    return r
                k = F32(k + d)
            return None

        return run

    def _s_test_(self, node):
        subject, *cases = node.children
        e = self.expr(subject)
        if e.type.ndim or base(e.type.name) not in ("num", "dnum", "string", "bool", "byte"):
            raise self.err(f"TEST on {e.type}", node)
        table, other = [], None
        for c in cases:
            if c.data == "default":
                other = self.block(c.children)
                continue
            exprs = [x for x in c.children if getattr(x, "data", None) not in _STMT_KINDS]
            stmts = c.children[len(exprs) :]
            vals = [self.expr(x, e.type).fn for x in exprs]
            table.append((vals, self.block(stmts)))
        subj = e.fn

        def run(fr):
            v = subj(fr)
            for vals, blk in table:
                for f in vals:
                    if f(fr) == v:
                        return blk(fr)
            return other(fr) if other is not None else None

        return run

    def _s_return_(self, node):
        r = self.routine
        if not node.children:
            if r is not None and r.kind == "func":
                raise self.err(f"RETURN without a value in FUNC {r.name}", node)
            ret = Ret(None)
            return lambda fr: ret
        if r is None or r.kind != "func":
            raise self.err("RETURN with a value outside a FUNC", node)
        v = self.expr(node.children[0], r.ret).fn
        return lambda fr: Ret(v(fr))

    def _s_raise_(self, node):
        st, line = self.state, line_of(node)
        if not node.children:
            if not self.in_handler:
                raise self.err("RAISE without an error number outside an ERROR handler", node)

            def reraise(fr):
                raise Propagate(st.current)

            return reraise
        v = self.expr(node.children[0], Type("errnum")).fn
        in_handler = self.in_handler

        def raise_new(fr):
            from cell.rapid.interp.consts import ERRNOS

            n = int(v(fr))
            name = next((k for k, x in ERRNOS.items() if x == n), f"ERRNO {n}")
            err = RapidRunError(name, "raised", line, errno=n)
            if in_handler:
                raise Propagate(err)
            raise err

        return raise_new

    def _s_retry(self, node):
        self._handler_only("RETRY", node)
        return lambda fr: RETRY

    def _s_trynext(self, node):
        self._handler_only("TRYNEXT", node)
        return lambda fr: TRYNEXT

    def _handler_only(self, what: str, node) -> None:
        if not self.in_handler:
            raise self.err(f"{what} outside an ERROR handler", node)

    def _s_exit_(self, node):
        line, src = line_of(node), self.state.source

        def stop(fr):
            raise RapidStopped("EXIT", line, src)

        return stop

    # --- calls ------------------------------------------------------------------------------
    def call(self, name_tok, args, node, function: bool) -> Expr:
        name = str(name_tok)
        what = "function" if function else "instruction"
        r = self.routines.get(name.lower())
        if r is not None:
            if (r.kind == "func") != function:
                raise self.err(f"{r.name} is a {'FUNC' if r.kind == 'func' else 'PROC'}, "
                               f"used as an {what}", node)  # fmt: skip
            return self._user_call(r, args, node)
        b = self.builtins.get(name.lower())
        if b is None:
            raise self.err(f"unknown {what} {name}", name_tok)
        if (b.kind == "func") != function:
            raise self.err(f"{b.name} is a {'function' if b.kind == 'func' else 'instruction'}, "
                           f"used as an {what}", node)  # fmt: skip
        return b.bind(self, args, node)

    def _user_call(self, r: Routine, args, node) -> Expr:
        opt = [a for a in args if getattr(a, "data", None) == "opt_arg"]
        if opt:
            raise self.err(f"{r.name} has no optional argument \\{opt[0].children[0]}", opt[0])
        if len(args) != len(r.params):
            raise self.err(f"{r.name} takes {len(r.params)} arguments, {len(args)} given", node)
        binders = []
        for p, a in zip(r.params, args, strict=True):
            if p.access == "in":
                f = self.expr(a, p.type).fn
                if base(p.type.name) not in _SCALARS:
                    f = (lambda g: lambda fr: copy_value(g(fr)))(f)
                binders.append((p.slot, f))
                continue
            if getattr(a, "data", None) != "ref":
                raise self.err(f"argument {p.name} of {r.name} ({p.access.upper()}) must be "
                               "a variable", a)  # fmt: skip
            loc, t, _ = self.location(a)
            if t != p.type:
                raise self.err(f"type mismatch: {t} for {p.access.upper()} {p.type} {p.name}", a)
            binders.append((p.slot, loc))
        line, src, is_func = line_of(node), self.state.source, r.kind == "func"

        def invoke(fr):
            new = [None] * r.scope.n_slots
            for slot, f in binders:
                new[slot] = f(fr)
            for slot, init in r.locals_init:
                new[slot] = init()
            try:
                res = r.run(new)
            except Propagate as p:
                raise p.err from None
            if is_func:
                if res is None or res.value is _NO_VALUE:
                    raise RapidStopped(f"FUNC {r.name} ended without RETURN", line, src)
                return res.value
            return None

        return Expr(invoke, r.ret or Type("none"))


_NO_VALUE = object()
_SCALARS = ("num", "dnum", "bool", "string", "byte")
_STMT_KINDS = {"assign", "call", "if_full", "if_compact", "while_", "for_", "test_", "return_",
               "raise_", "retry", "trynext", "exit_"}  # fmt: skip
__all__ = ["Propagate", "Ret", "StmtCompiler", "assignable", "converter"]
