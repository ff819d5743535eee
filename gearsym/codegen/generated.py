"""The committed ``generated/<model>/`` folders: write them, or check them byte for byte."""
from __future__ import annotations

import tempfile
from dataclasses import dataclass, field
from pathlib import Path

from ..files.atomic import writing
from ..options import Integration
from ..system import FirstOrderSystem
from .code_files import source_file
from .library import library_describes
from .compiler import compile_library
from .functions import build_functions
from .loops import LoopOptions
from .generate import code_hash, write_code
from .fastest_mode import chosen_for


@dataclass
class GenerateReport:
    name: str
    source: Path
    hash: str
    size: int
    library: Path | None = None
    compile_seconds: float = 0.0
    stale: list[Path] = field(default_factory=list)


def generate_model(system: FirstOrderSystem, out: Path, options: Integration = Integration(), *,
                   check: bool = False, compile: bool = True) -> GenerateReport:
    """Write ``out/<model>/<model>.c`` and ``manifest.json`` for ``system`` compiled with ``options``;
    with ``check``, compare instead of writing."""
    options = chosen_for(options, system)
    loops = LoopOptions.of(options, system.cycles)
    digest = code_hash(system, loops)
    target = Path(out) / system.name
    if check:
        fresh = _fresh_code(system, loops, digest)
        stale = [target / name for name in fresh
                 if not (target / name).is_file() or (target / name).read_bytes() != fresh[name]]
        source = source_file(system.name)
        return GenerateReport(system.name, target / source, digest, len(fresh[source]), stale=stale)
    mf = build_functions(system, loops)
    with writing(target):
        code = write_code(mf, target, digest)
    report = GenerateReport(system.name, code.source, digest, code.source.stat().st_size)
    if compile:
        # (described as compile_model describes it: the library runs load)
        lib = compile_library(code.source, system.name, describes=library_describes(system, digest))
        report.library, report.compile_seconds = lib.path, lib.seconds if lib.compiled else 0.0
    return report


#: the files of a code hash as this process generated them (file name -> bytes): the same hash is the same C (what the
#: hash is for), so a check of a model checked before in the process (`gearsym compile --check` after the tests' own
#: checks, a notebook checking twice) compares with these instead of building and printing the model's C again
_FRESH: dict[str, dict[str, bytes]] = {}


def _fresh_code(system: FirstOrderSystem, loops: LoopOptions, digest: str) -> dict[str, bytes]:
    """The C, lanes' C and manifest of ``system`` with ``loops`` (hash ``digest``), by file name."""
    if digest not in _FRESH:
        with tempfile.TemporaryDirectory() as tmp:
            fresh = write_code(build_functions(system, loops), Path(tmp) / system.name, digest)
            _FRESH[digest] = {p.name: p.read_bytes() for p in (fresh.source, fresh.lanes, fresh.manifest)}
    return _FRESH[digest]
