"""Large arrays the simulator draws from fixed seeds, kept in the user's cache folder.

The surface texture (64 MB) and the noise bank (30 MB) take every new process 1.7 s of CPU to
draw, and the demo and the tests start many processes (the render workers, pytest's). They
depend only on their seed, this code and the versions of NumPy and OpenCV, so the first process
writes each to the user's cache folder (:func:`measure.user_cache.cache_dir`, as the demo's
cached tours) and every later one maps the file read-only: the same values, shared in the page
cache. A file that cannot be read or written is drawn again (and the drawing used): the cache
only saves time.
"""

from __future__ import annotations

import hashlib
import logging
import os
import tempfile
from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np

from measure.user_cache import cache_dir

log = logging.getLogger(__name__)


def cached_array(
    name: str, source: str, shape: tuple[int, ...], draw: Callable[[], np.ndarray]
) -> np.ndarray:
    """``draw()`` (an array of ``shape``, float32), read-only, from the cache when there:
    ``name`` and a digest of ``source`` (the code that draws it) and the library versions name
    the file."""
    digest = hashlib.sha256(
        "\n".join((source, np.__version__, cv2.__version__, repr(shape))).encode()
    ).hexdigest()[:24]
    path = cache_dir() / f"{name}-{digest}.npy"
    if path.is_file():
        try:
            arr = np.load(path, mmap_mode="r")
            if arr.shape == shape and arr.dtype == np.float32:
                return arr
            log.warning("%s: shape %s, dtype %s: drawn again", path, arr.shape, arr.dtype)
        except (OSError, ValueError) as exc:
            log.warning("%s: unreadable (%s): drawn again", path, exc)
    arr = draw()
    _write(path, arr)
    arr.setflags(write=False)
    return arr


def _write(path: Path, arr: np.ndarray) -> None:
    """Write ``arr`` to ``path`` whole or not at all (a temporary file renamed over it)."""
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=path.stem, suffix=".tmp")
        try:
            with os.fdopen(fd, "wb") as f:
                np.save(f, arr)
            os.replace(tmp, path)
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise
    except OSError as exc:
        log.warning("%s: not cached (%s)", path, exc)
