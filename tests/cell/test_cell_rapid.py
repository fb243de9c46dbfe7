"""The RAPID controller module is kept in step with the Python side: shared constants, the
dispatch of every request, and its CRC-32 routine (transliterated and run) against zlib."""

from __future__ import annotations

import random
import re
import zlib
from pathlib import Path

import pytest

import cell
from cell.link import frame as fr
from cell.link import messages as m

MOD = Path(cell.__file__).parent / "rapid" / "HolecellLink.mod"
TEXT = MOD.read_text()


def _consts() -> dict[str, object]:
    out: dict[str, object] = {}
    for kind, name, value in re.findall(r"CONST (num|dnum|string) (\w+) := ([^;]+);", TEXT):
        out[name] = value.strip('"') if kind == "string" else float(value)
    return {k: int(v) if isinstance(v, float) and v.is_integer() else v for k, v in out.items()}


C = _consts()


def test_framing_constants_match() -> None:
    assert bytes([C["HC_SYNC1"], C["HC_SYNC2"]]) == fr.SYNC
    assert C["HC_MAX_PAYLOAD"] == fr.MAX_PAYLOAD
    assert C["HC_CRC32_POLY"] == 0xEDB88320
    assert C["HC_CRC32_INIT"] == 0xFFFFFFFF
    assert C["HC_CRC32_CHECK"] == fr.CRC32_CHECK == zlib.crc32(b"123456789")
    assert C["HC_PROTOCOL_VERSION"] == m.PROTOCOL_VERSION
    assert C["HC_ROWS_PER_CHUNK"] == m.ROWS_PER_CHUNK
    assert C["HC_STOPS_PER_CHUNK"] == m.STOPS_PER_CHUNK


@pytest.mark.parametrize(
    ("prefix", "enum"), [("MSG_", m.Msg), ("NAK_", m.Nak), ("ST_", m.State), ("FLT_", m.Fault)]
)
def test_codes_match(prefix: str, enum: type) -> None:
    rapid = {k[len(prefix) :]: v for k, v in C.items() if k.startswith(prefix)}
    assert rapid == {e.name: int(e) for e in enum}


def test_every_request_is_dispatched() -> None:
    body = TEXT[
        TEXT.index("PROC hcDispatch()") : TEXT.index("ENDPROC", TEXT.index("PROC hcDispatch()"))
    ]
    for msg in m.Msg:
        if msg < 0x80:
            assert f"CASE MSG_{msg.name}:" in body, msg.name


def _block(start: str, end: str) -> list[str]:
    i = TEXT.index(start)
    return [ln.strip() for ln in TEXT[i : TEXT.index(end, i)].splitlines()[1:]]


def _transliterate(lines: list[str], indent: int = 1) -> str:
    """The few RAPID statements the CRC routines use, as Python (one line each)."""
    out, level = [], indent
    for ln in lines:
        if not ln or ln.startswith(("VAR ", "!")):
            continue
        if ln.startswith(("ENDFOR", "ENDIF")):
            level -= 1
            continue
        if ln == "ELSE":
            out.append("    " * (level - 1) + "else:")
            continue
        py = ln.rstrip(";").replace(":=", "=").replace("{", "[").replace("}", "]")
        if mt := re.fullmatch(r"FOR (\w+) FROM (.+) TO (.+) DO", py):
            py = f"for {mt[1]} in range({mt[2]}, ({mt[3]}) + 1):"
        elif mt := re.fullmatch(r"IF (.+) THEN", py):
            py = "if " + mt[1].replace(" = ", " == ") + ":"
        elif py.startswith("RETURN "):
            py = "return " + py[7:]
        out.append("    " * level + py)
        if py.endswith(":"):
            level += 1
    return "\n".join(out)


def test_rapid_crc_routine_reproduces_zlib() -> None:
    init = _transliterate(_block("PROC hcCrcInit()", "ENDPROC"))
    byte = _transliterate(_block("FUNC dnum hcCrcByte(dnum crc, num b)", "ENDFUNC"))
    src = f"def hcCrcInit():\n{init}\n\ndef hcCrcByte(crc, b):\n{byte}\n"
    env: dict = {
        "HC_CRC32_POLY": C["HC_CRC32_POLY"],
        "hcCrcTable": {},
        "NumToDnum": int,
        "DnumToNum": int,
        "BitAndDnum": lambda a, b: a & b,
        "BitXOrDnum": lambda a, b: a ^ b,
        "BitRShDnum": lambda a, n: a >> n,
    }
    exec(compile(src, str(MOD), "exec"), env)
    env["hcCrcInit"]()
    rng = random.Random(0)
    for data in [b"123456789", b"", *(rng.randbytes(rng.randrange(1, 300)) for _ in range(20))]:
        crc = C["HC_CRC32_INIT"]
        for b in data:
            crc = env["hcCrcByte"](crc, b)
        assert crc ^ C["HC_CRC32_INIT"] == zlib.crc32(data)


def test_module_crc_in_the_interpreter_reproduces_zlib() -> None:
    """The module's own hcCrcInit and hcCrcRaw, run by the RAPID interpreter (num in single
    precision, dnum in double), give zlib's CRC-32."""
    from cell.rapid.interp import Program
    from cell.rapid.interp.rtypes import RawBytes

    program = Program.from_file(MOD)
    program.run("hcCrcInit", host=None)
    rng = random.Random(1)
    for data in [b"123456789", b"", *(rng.randbytes(rng.randrange(1, 300)) for _ in range(5))]:
        raw = RawBytes()
        raw.data[: len(data)], raw.n = data, len(data)
        crc = program.call("hcCrcRaw", C["HC_CRC32_INIT"], raw, 1, len(data))
        assert int(crc) ^ C["HC_CRC32_INIT"] == zlib.crc32(data)
