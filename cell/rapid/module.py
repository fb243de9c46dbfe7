"""``HolecellLink.mod`` with the settings of one cell: its CONSTs rewritten in the text, as an
integrator would edit them before loading the module on the controller (``holecell controller
deploy``). The interpreter (:mod:`cell.rapid.interp`) sets the same CONSTs at load instead."""

from __future__ import annotations

import re
from pathlib import Path

from cell.errors import CellError

MODULE_PATH = Path(__file__).parent / "HolecellLink.mod"
#: the CONSTs a cell sets: name -> RAPID type
SETTINGS = {
    "HC_MODEL": "string",
    "HC_NAME": "string",
    "HC_TRANSPORT": "string",
    "HC_PORT": "string",
    "HC_SOCKET_ADDRESS": "string",
    "HC_SOCKET_PORT": "num",
    "HC_N_TEMPS": "num",
    "HC_LINK_TIMEOUT_S": "num",
}


def _literal(name: str, value: object) -> str:
    if SETTINGS[name] == "string":
        text = str(value)
        if '"' in text or "\\" in text or len(text) > 80 or not text.isprintable():
            raise CellError(f"RAPID module: {name} = {text!r} cannot be a RAPID string "
                            "(no quotes or backslashes, at most 80 characters)")  # fmt: skip
        return f'"{text}"'
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise CellError(f"RAPID module: {name} = {value!r} must be a number")
    return repr(int(value)) if float(value).is_integer() else repr(float(value))


def link_module(settings: dict[str, object], text: str | None = None) -> str:
    """The module text with each CONST of ``settings`` (names of :data:`SETTINGS`) set."""
    text = MODULE_PATH.read_text() if text is None else text
    for name, value in settings.items():
        if name not in SETTINGS:
            raise CellError(f"RAPID module: {name} is not a setting ({', '.join(SETTINGS)})")
        pattern = re.compile(rf"^(\s*CONST\s+{SETTINGS[name]}\s+{name}\s*:=\s*)[^;]*;", re.M)
        literal = _literal(name, value)
        text, n = pattern.subn(lambda m, v=literal: f"{m.group(1)}{v};", text)
        if n != 1:
            raise CellError(f"RAPID module: CONST {name} found {n} times, expected once")
    return text


def link_settings(robot_model: str, port: str, name: str = "irc5-holecell",
                  n_temps: int = 6) -> dict[str, object]:  # fmt: skip
    """The settings for a cell whose computer opens the link at ``port``:
    ``socket://ADDRESS:PORT`` (the controller serves RAPID socket messaging there) or a serial
    device (the controller's ``com1:``)."""
    out: dict[str, object] = {"HC_MODEL": robot_model, "HC_NAME": name, "HC_N_TEMPS": n_temps}
    if port.startswith("socket://"):
        address, _, p = port[len("socket://") :].rpartition(":")
        if not address or not p.isdigit() or not 0 < int(p) < 65536:
            raise CellError(f"--port {port}: expected socket://ADDRESS:PORT")
        out.update(HC_TRANSPORT="socket", HC_SOCKET_ADDRESS=address, HC_SOCKET_PORT=int(p))
    else:
        out["HC_TRANSPORT"] = "serial"
    return out
