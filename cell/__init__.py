"""The inspection cell: configuration, controller link, runner, store, recording and CLI."""
