"""One module per ``holecell`` subcommand; each has ``register(subparsers)``.

A command's handler takes the parsed ``argparse.Namespace`` and returns the
process exit code. User mistakes raise an error derived from one of the
package bases (``CellError``, ``PlanningError``, ``MeasurementError``,
``RobotModelError``); :func:`cell.cli.main` prints its message, no traceback.
"""
