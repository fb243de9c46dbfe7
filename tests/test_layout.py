"""The repository's layout: the four packages at the top, imports pointing one way only."""

from __future__ import annotations

import ast
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("robots", "planner", "measure", "cell")
# package -> the packages it may import (besides itself)
ALLOWED = {
    "robots": set(),
    "measure": set(),
    "planner": {"robots"},
    "cell": {"robots", "planner", "measure"},
}


def _imported_packages(path: Path) -> set[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    names: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(alias.name.split(".")[0] for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names.add(node.module.split(".")[0])
    return names & set(PACKAGES)


def test_imports_point_one_way() -> None:
    wrong = []
    for package in PACKAGES:
        for path in sorted((ROOT / package).rglob("*.py")):
            for other in _imported_packages(path) - {package} - ALLOWED[package]:
                wrong.append(f"{path.relative_to(ROOT)} imports {other}")
    assert not wrong, "\n".join(wrong)


def test_top_level_and_no_outside_paths() -> None:
    tracked = subprocess.run(
        ["git", "ls-files"], cwd=ROOT, capture_output=True, text=True, check=True
    ).stdout.split()
    top = {name.split("/")[0] for name in tracked}
    assert {*PACKAGES, "tests", "pyproject.toml", "README.md"} <= top
    assert "src" not in top
    pointing_out = [
        name
        for name in tracked
        if name.endswith((".py", ".md", ".toml", ".yaml", "Makefile"))
        and "../" + "shared" in (ROOT / name).read_text(encoding="utf-8", errors="replace")
    ]
    assert not pointing_out, pointing_out


def test_tests_and_benchmarks_are_not_installed_packages(tmp_path: Path) -> None:
    """From a folder outside the repository, the installed packages import and the test and
    benchmark folders do not."""
    import sys

    code = (
        "import importlib.util, cell, planner, measure, robots\n"
        "print([n for n in ('tests', 'benchmarks') if importlib.util.find_spec(n)])"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, check=True
    ).stdout.strip()
    assert out == "[]"
