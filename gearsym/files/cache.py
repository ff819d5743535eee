"""Where the user's cache is asked to be: ``$GEARSYM_CACHE``, else ``$XDG_CACHE_HOME/gearsym`` or ``~/.cache/gearsym``.

One place for it: the compiled libraries (:mod:`gearsym.codegen.compiler`) and the small answers kept beside them
(:mod:`.memo`) live under the same folder."""
from __future__ import annotations

import os
from pathlib import Path


def configured_cache() -> Path:
    """Where the cache is asked to be: ``$GEARSYM_CACHE``, else ``$XDG_CACHE_HOME/gearsym`` or ``~/.cache/gearsym``."""
    root = os.environ.get("GEARSYM_CACHE")
    if root:
        return Path(root)
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "gearsym"
