"""Session-wide test settings: holecell's cache folder is a temporary one (no test writes
to the user's cache; a run that plans once and reads back still works as in use)."""

from __future__ import annotations

import os

import pytest

from cell.demo.caltour_cache import CACHE_ENV


@pytest.fixture(scope="session", autouse=True)
def _private_cache(tmp_path_factory: pytest.TempPathFactory):
    before = os.environ.get(CACHE_ENV)
    os.environ[CACHE_ENV] = str(tmp_path_factory.mktemp("holecell-cache"))
    yield
    if before is None:
        os.environ.pop(CACHE_ENV, None)
    else:
        os.environ[CACHE_ENV] = before
