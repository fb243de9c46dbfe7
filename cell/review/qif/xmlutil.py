"""Small helpers for building QIF elements with lxml: the namespace, decimals, ids.

Numbers are written as ``xs:decimal`` text (fixed point, no exponent: the QIF value types
derive from ``xs:decimal``) with the shortest digits that read back to the same float, so a
value read from ``report.qif`` equals the one in ``report.json`` exactly.
"""

from __future__ import annotations

from collections.abc import Iterable
from decimal import Decimal

from lxml import etree

from cell.review.qif.validator import NS

Q = f"{{{NS}}}"


def dec(v: float) -> str:
    """``v`` as an ``xs:decimal`` literal (fixed point; exactly ``float(dec(v)) == v``)."""
    f = float(v)
    if f != f or f in (float("inf"), float("-inf")):
        raise ValueError(f"not a finite number: {v!r}")
    text = format(Decimal(repr(f)), "f")
    return "0" if text in ("-0", "-0.0") else text


def vec(v: Iterable[float]) -> str:
    """A QIF point or vector: three decimals separated by spaces."""
    return " ".join(dec(x) for x in v)


def sub(parent: etree._Element, tag: str, text: str | None = None, **attrs: str) -> etree._Element:
    """Append ``<tag>`` in the QIF namespace to ``parent`` with ``text`` and attributes."""
    e = etree.SubElement(parent, Q + tag, {k: str(v) for k, v in attrs.items()})
    if text is not None:
        e.text = text
    return e


def counted(parent: etree._Element, tag: str) -> etree._Element:
    """A QIF list element (``n`` attribute set by :func:`finish_counts`)."""
    return sub(parent, tag, n="0")


def finish_counts(root: etree._Element) -> None:
    """Set every ``n`` attribute to its element's number of children."""
    for e in root.iter():
        if "n" in e.attrib:
            e.set("n", str(len(e)))


def ids_list(parent: etree._Element, tag: str, ids: Iterable[int]) -> etree._Element:
    """``<tag n=K><Id>..</Id>...</tag>``: a QIF array of references."""
    e = counted(parent, tag)
    for i in ids:
        sub(e, "Id", str(i))
    return e


class Ids:
    """The QIF ids of one document: 1, 2, 3, ... (``idMax`` is the last one handed out)."""

    def __init__(self) -> None:
        self.last = 0

    def next(self) -> int:
        self.last += 1
        return self.last
