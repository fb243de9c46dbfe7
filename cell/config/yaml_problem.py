"""One line for a YAML syntax error: where (line, column, 1-based) and what, for a refusal.

PyYAML's own message spans several lines (the context, the problem, a caret drawing); a
refusal is one line naming the file, so :func:`yaml_problem` keeps the position and the words.
"""

from __future__ import annotations

import yaml

from cell.errors import NO_VALUE


def yaml_problem(exc: yaml.YAMLError) -> tuple[str, object, str]:
    """``(where, NO_VALUE, message)`` of a YAML error: ``where`` is ``line L, column C`` of the
    problem (``(yaml)`` when PyYAML gives no position); the message is one line."""
    mark = getattr(exc, "problem_mark", None) or getattr(exc, "context_mark", None)
    problem = getattr(exc, "problem", None)
    context = getattr(exc, "context", None)
    words = problem or (str(exc).splitlines() or ["syntax error"])[0]
    if context and getattr(exc, "context_mark", None) is not None:
        cm = exc.context_mark
        words += f" ({context} from line {cm.line + 1})"
    where = "(yaml)" if mark is None else f"line {mark.line + 1}, column {mark.column + 1}"
    return where, NO_VALUE, f"not valid YAML: {' '.join(words.split())}"
