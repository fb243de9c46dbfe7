"""The folder holecell keeps its caches in: what the first run computes and later runs read
(the demo's planned tours, the simulator's seeded arrays)."""

from __future__ import annotations

import os
from pathlib import Path

import platformdirs

#: the environment variable that moves the cache folder (tests, shared machines)
CACHE_ENV = "HOLECELL_CACHE_DIR"


def cache_dir() -> Path:
    """``$HOLECELL_CACHE_DIR``, else the user's cache folder for holecell."""
    env = os.environ.get(CACHE_ENV)
    return Path(env) if env else Path(platformdirs.user_cache_dir("holecell"))
