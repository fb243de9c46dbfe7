"""The interpreter refuses what RobotWare refuses, by name and line: a suite of deliberately
broken modules (``rapid_modules/broken``), each naming in its first line what is refused, when
(``load``: before running; ``run``: the program stops) and on which line."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from cell.rapid.interp import Program, RapidLoadError, RapidStopped

BROKEN = sorted((Path(__file__).parent / "rapid_modules" / "broken").glob("*.mod"))


def _expected(path: Path) -> tuple[str, int, str]:
    head = path.read_text().splitlines()[0]
    mt = re.fullmatch(r"! refused: (load|run) line (\d+): (.+)", head)
    assert mt, f"{path.name}: first line {head!r}"
    return mt[1], int(mt[2]), mt[3]


def test_the_suite_covers_the_four_kinds_the_issue_names() -> None:
    names = {p.stem for p in BROKEN}
    assert {"undeclared_variable", "wrong_argument_name", "type_mismatch",
            "index_out_of_range"} <= names  # fmt: skip


@pytest.mark.parametrize("path", BROKEN, ids=[p.stem for p in BROKEN])
def test_broken_module_is_refused_by_name_and_line(path: Path) -> None:
    when, line, text = _expected(path)
    if when == "load":
        with pytest.raises(RapidLoadError) as exc:
            Program.from_file(path)
    else:
        program = Program.from_file(path)
        with pytest.raises(RapidStopped) as exc:
            program.run("main", host=None)
    assert exc.value.line == line, str(exc.value)
    assert text in str(exc.value)
    assert str(exc.value).startswith(f"{path}:{line}: ")


def test_the_shipped_module_loads() -> None:
    from cell.sim.rapid_controller import MODULE

    program = Program.from_file(MODULE)
    assert {"hcmain", "hconestop", "hcdispatch"} <= set(program.routines)
