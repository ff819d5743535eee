"""What this process has loaded: one table of compiled models, their lanes and the fit's windows, and the one
loader of a compiled library through ctypes.

A model is kept by its code hash and backend, so that a second compile of the same code (another model object,
other values) reuses its functions; the start-up cache (:mod:`gearsym.cached`) loads a library into the same
table without generating anything; the lanes and the windows are kept by what their C was made from. Each key is
made once, however many threads ask at once (a library compiled and loaded once). Nothing here needs SymPy.
"""
from __future__ import annotations

import ctypes
import threading
from collections.abc import Callable, Hashable
from pathlib import Path
from typing import TypeVar

T = TypeVar("T")

#: (kind, ...) -> what this process loaded: ("model", code hash, backend), ("lanes", code hash, library),
#: ("windows", equations, channels, backend), ("library", path)
LOADED: dict[tuple, object] = {}
_GUARD = threading.Lock()
_MAKING: dict[Hashable, threading.Lock] = {}


def loaded(key: tuple) -> object | None:
    """What this process loaded under ``key``, or None."""
    return LOADED.get(key)


def keep(key: tuple, value: T) -> T:
    """``value``, kept under ``key`` for the rest of the process."""
    LOADED[key] = value
    return value


def load_once(key: tuple, load: Callable[[], T]) -> T:
    """What this process loaded under ``key``: made by ``load()`` the first time (once, whichever threads ask)."""
    found = LOADED.get(key)
    if found is not None:
        return found
    with _GUARD:
        making = _MAKING.setdefault(key, threading.Lock())
    with making:
        found = LOADED.get(key)
        if found is None:
            found = LOADED[key] = load()
        return found


def open_library(path: Path) -> ctypes.CDLL:
    """The shared library at ``path`` (one the cache compiled and checked), loaded once per process."""
    return load_once(("library", str(path)), lambda: ctypes.CDLL(str(path)))
