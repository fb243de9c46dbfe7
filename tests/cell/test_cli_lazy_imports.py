"""``holecell COMMAND`` imports only that command's module; the table it uses is what the
modules register."""

from __future__ import annotations

import argparse
import importlib
import subprocess
import sys

from cell import cli


def test_the_command_table_is_what_each_module_registers() -> None:
    assert set(cli.COMMAND_OF_MODULE) == set(cli.COMMAND_MODULES)
    for module in cli.COMMAND_MODULES:
        parser = argparse.ArgumentParser()
        sub = parser.add_subparsers()
        importlib.import_module(f"cell.commands.{module}").register(sub)
        assert list(sub.choices) == [cli.COMMAND_OF_MODULE[module]], module


def test_a_named_command_imports_its_module_alone() -> None:
    assert cli._modules_for(["plan", "cell.yaml", "--quiet"]) == ("plan_cmd",)
    assert cli._modules_for(["-v", "plan-batch", "a.yaml"]) == ("plan_batch_cmd",)
    assert cli._modules_for(["--help"]) == cli.COMMAND_MODULES
    assert cli._modules_for([]) == cli.COMMAND_MODULES
    assert cli._modules_for(["plna"]) == cli.COMMAND_MODULES  # argparse lists the choices


def test_holecell_plan_does_not_import_the_other_commands_libraries() -> None:
    code = (
        "import sys; from cell.cli import build_parser; "
        "build_parser(['plan']).parse_args(['plan', '--quiet']); "
        "print(sorted(m for m in ('rerun', 'cv2', 'cell.commands.run_cmd') if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"
