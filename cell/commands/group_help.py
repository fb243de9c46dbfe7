"""The handler of a command group called without its action (``holecell thermal``,
``holecell truth``, ``holecell cell``): the group's help, exit code 2."""

from __future__ import annotations

import argparse
from collections.abc import Callable


def help_handler(parser: argparse.ArgumentParser) -> Callable[[argparse.Namespace], int]:
    """A handler that prints ``parser``'s help and returns exit code 2."""

    def handler(args: argparse.Namespace) -> int:
        parser.print_help()
        return 2

    return handler
