"""Where a model's generated C stands, and what its files are: one rule for the model's library, its lanes, the
FMU and a packed model.

The C of the code ``digest`` is in the committed ``generated/<model>/`` if that folder's manifest carries the
hash (no need to generate it again), else in the cache (made private). Each file in the cache has a record of
what it is (:mod:`.trust`), and is compiled only if its bytes are those gearsym wrote. Nothing here needs SymPy
or CasADi: a cached model's lanes are found from files.
"""
from __future__ import annotations

import json
from pathlib import Path

from ..files.paths import GENERATED_DIR
from .compiler import cache_dir


def source_file(name: str) -> str:
    """The file name of a model's C: CasADi's functions with the printed loops (:mod:`.printed`)."""
    return f"{name}.c"


def lanes_file(name: str) -> str:
    """The file name of a model's lanes' C (:mod:`.lanes`), beside its ``<model>.c``, which it includes."""
    return f"{name}_lanes.c"


def read_manifest(directory: Path) -> dict | None:
    """The ``manifest.json`` of a folder of generated C, or None (missing or not JSON)."""
    path = Path(directory) / "manifest.json"
    try:
        data = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) else None


def is_committed(directory: Path, name: str) -> bool:
    """Whether ``directory`` is the committed ``generated/<name>/`` (whose files the repository holds)."""
    return Path(directory) == GENERATED_DIR / name


def code_directory(name: str, digest: str) -> Path:
    """Where the C of the code ``digest`` is: the committed ``generated/<model>/`` if its manifest carries this
    hash, else the cache."""
    committed = GENERATED_DIR / name
    if (read_manifest(committed) or {}).get("hash") == digest:
        return committed
    return cached_code_directory(name, digest)


def cached_code_directory(name: str, digest: str) -> Path:
    """Where the cache keeps the C of the code ``digest`` when it is generated (or received) here (made private)."""
    return cache_dir("code", f"{name}-{digest[:16]}")


def source_describes(name: str, digest: str) -> dict:
    """What the generated C of a model is, as its record in the cache keeps it."""
    return {"model": name, "code": digest}


def lanes_describes(name: str, digest: str) -> dict:
    """What the lanes' C of a model is, as its record in the cache keeps it."""
    return {"model": f"{name}_lanes", "code": digest}
