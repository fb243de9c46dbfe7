"""A small thread-safe store of the renderer's per-camera results, the least recently used
dropped past its size (the ray grids, backgrounds and light maps every view of a camera
shares)."""

from __future__ import annotations

import threading
from collections import OrderedDict
from collections.abc import Hashable
from typing import Generic, TypeVar

T = TypeVar("T")


class Lru(Generic[T]):
    """At most ``size`` results by key. A result is built outside the lock (:meth:`lookup`
    misses, the caller builds, :meth:`keep` stores): two threads may build the same one."""

    def __init__(self, size: int) -> None:
        self.size = size
        self._items: OrderedDict[Hashable, T] = OrderedDict()
        self._lock = threading.Lock()

    def lookup(self, key: Hashable) -> T | None:
        """The result kept for ``key`` (now the most recently used), or None."""
        with self._lock:
            hit = self._items.get(key)
            if hit is not None:
                self._items.move_to_end(key)
            return hit

    def keep(self, key: Hashable, value: T) -> T:
        """Store ``value`` for ``key`` (dropping the least recently used past the size);
        returns it."""
        with self._lock:
            self._items[key] = value
            while len(self._items) > self.size:
                self._items.popitem(last=False)
        return value
