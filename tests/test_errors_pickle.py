"""Every error of :mod:`cell` survives pickling (a worker process's refusal reaches the caller as
raised): its type, message and payload."""

from __future__ import annotations

import pickle

from cell.calibration.errors import CalibrationDataError, StopCorrectionError
from cell.errors import ConfigError


def test_errors_pickle_with_their_message_and_payload() -> None:
    for error in (
        CalibrationDataError("tour", "left image: no board", "v7"),
        StopCorrectionError("run", 3, "H1", "too far"),
        ConfigError("cell.yaml", [("robot.model", "x", "unknown")]),
    ):
        back = pickle.loads(pickle.dumps(error))
        assert type(back) is type(error)
        assert str(back) == str(error)
        assert back.__dict__ == error.__dict__
    assert pickle.loads(pickle.dumps(CalibrationDataError("tour", "bad", "v7"))).row == "v7"
