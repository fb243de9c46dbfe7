"""The simulator's seeded arrays kept in the cache folder: drawn once, then read back the same;
a damaged file or an unwritable folder costs a drawing, never a wrong array."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from measure.synth.disk_cache import cached_array
from measure.user_cache import CACHE_ENV


def _drawer(calls: list[int]):
    def draw() -> np.ndarray:
        calls.append(1)
        return np.random.default_rng(3).standard_normal((40, 30), dtype=np.float32)

    return draw


def test_an_array_is_drawn_once_and_then_read(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.setenv(CACHE_ENV, str(tmp_path))
    calls: list[int] = []
    first = cached_array("t", "code v1", (40, 30), _drawer(calls))
    again = cached_array("t", "code v1", (40, 30), _drawer(calls))
    assert calls == [1]
    np.testing.assert_array_equal(first, again)
    assert not again.flags.writeable
    cached_array("t", "code v2", (40, 30), _drawer(calls))  # other code: another file
    assert calls == [1, 1] and len(list(tmp_path.glob("t-*.npy"))) == 2


def test_a_damaged_file_is_drawn_again(tmp_path: Path, monkeypatch, caplog) -> None:
    monkeypatch.setenv(CACHE_ENV, str(tmp_path))
    calls: list[int] = []
    good = cached_array("t", "code", (40, 30), _drawer(calls))
    (path,) = tmp_path.glob("t-*.npy")
    path.write_bytes(b"not an array")
    back = cached_array("t", "code", (40, 30), _drawer(calls))
    assert calls == [1, 1] and "unreadable" in caplog.text
    np.testing.assert_array_equal(back, good)
    np.testing.assert_array_equal(np.load(path), good)  # and written again


def test_an_unwritable_folder_still_gives_the_array(tmp_path: Path, monkeypatch, caplog) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("a file where the folder would be")
    monkeypatch.setenv(CACHE_ENV, str(blocker / "cache"))
    calls: list[int] = []
    arr = cached_array("t", "code", (40, 30), _drawer(calls))
    assert arr.shape == (40, 30) and calls == [1] and "not cached" in caplog.text


def test_a_file_of_another_shape_is_drawn_again(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.setenv(CACHE_ENV, str(tmp_path))
    calls: list[int] = []
    cached_array("t", "code", (40, 30), _drawer(calls))
    (path,) = tmp_path.glob("t-*.npy")
    np.save(path, np.zeros((30, 40), np.float32))
    assert cached_array("t", "code", (40, 30), _drawer(calls)).shape == (40, 30)
    assert calls == [1, 1]
