"""The one atomic writer: a failed write leaves the old file whole and no temporary behind."""

from __future__ import annotations

from pathlib import Path

import pytest

from robots.files import write_text_atomic


def test_write_replaces_and_a_failed_write_keeps_the_old_file(tmp_path: Path) -> None:
    target = tmp_path / "model.json"
    assert write_text_atomic(target, "first\n") == target
    write_text_atomic(target, "second\n")
    assert target.read_text() == "second\n"
    with pytest.raises(UnicodeEncodeError):
        write_text_atomic(target, "half written \ud800")  # cannot be encoded: the write fails
    assert target.read_text() == "second\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["model.json"]
