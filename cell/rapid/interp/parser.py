"""The RAPID parser: the grammar of ``grammar.lark`` (LALR, Lark) applied to a module's text;
a syntax error names the line and column."""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

from lark import Lark, Tree
from lark.exceptions import UnexpectedCharacters, UnexpectedInput, UnexpectedToken

from cell.rapid.interp.errors import RapidLoadError

GRAMMAR = Path(__file__).with_name("grammar.lark")


@lru_cache(maxsize=1)
def _parser() -> Lark:
    return Lark(
        GRAMMAR.read_text(), parser="lalr", propagate_positions=True, maybe_placeholders=False
    )


@lru_cache(maxsize=16)
def parse(text: str, source: str = "<module>") -> Tree:
    """The parse tree of one module (``module`` node); RapidLoadError on a syntax error. Kept
    for the same text (the compiler only reads the tree)."""
    try:
        return _parser().parse(text).children[0]
    except UnexpectedToken as exc:
        tok = exc.token
        got = "end of file" if tok.type == "$END" else repr(str(tok))
        raise RapidLoadError(
            f"syntax error at {got} (column {exc.column})", exc.line, source
        ) from None
    except UnexpectedCharacters as exc:
        raise RapidLoadError(f"unexpected character {exc.char!r} (column {exc.column})", exc.line,
                             source) from None  # fmt: skip
    except UnexpectedInput as exc:
        raise RapidLoadError(f"syntax error (column {exc.column})", exc.line, source) from None
