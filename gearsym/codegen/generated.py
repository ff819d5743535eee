"""The committed ``generated/<model>/`` folders: write them, or check them byte for byte."""
from __future__ import annotations

import tempfile
from dataclasses import dataclass, field
from pathlib import Path

from ..files.atomic import writing
from ..options import Integration
from ..system import FirstOrderSystem
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
    mf = build_functions(system, loops)
    if check:
        with tempfile.TemporaryDirectory() as tmp:
            fresh = write_code(mf, Path(tmp) / system.name, digest)
            stale = [target / p.name for p in (fresh.source, fresh.lanes, fresh.manifest)
                     if not (target / p.name).is_file() or (target / p.name).read_bytes() != p.read_bytes()]
            return GenerateReport(system.name, target / fresh.source.name, digest, fresh.source.stat().st_size,
                                  stale=stale)
    with writing(target):
        code = write_code(mf, target, digest)
    report = GenerateReport(system.name, code.source, digest, code.source.stat().st_size)
    if compile:
        # (described as compile_model describes it: the library runs load)
        lib = compile_library(code.source, system.name, describes=library_describes(system, digest))
        report.library, report.compile_seconds = lib.path, lib.seconds if lib.compiled else 0.0
    return report
