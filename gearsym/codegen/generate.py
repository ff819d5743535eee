"""C source and manifest for one model, byte for byte the same for the same model.

The hash that names the code is computed from the symbolic model and the loop
options (not from parameter values, which are runtime inputs), so a cache can
be consulted before any CasADi graph is built.
"""
from __future__ import annotations

import hashlib
import json
import os
import tempfile
from dataclasses import asdict, dataclass
from pathlib import Path

import casadi as ca

from ..files.atomic import write_atomically
from ..system import FirstOrderSystem
from .functions import ModelFunctions
from .loops import LoopOptions
from .code_files import lanes_file, source_file
from .expression_text import ExpressionText
from .lanes import lanes_source
from .printed import LOOP_NAMES, pieces, print_loops, stand_in

#: bump when the generated code changes for the same model and options
CODEGEN_VERSION = 2

#: the modules whose text determines the generated C; their bytes are part of the hash, so an edit
#: can never leave a stale library or committed C in use (the tests then ask to regenerate)
_GENERATOR_SOURCES = ("translate.py", "time_tables.py", "casadi_symbols.py", "rk4.py", "switching.py", "crossing.py",
                      "period_loops.py", "tables.py", "functions.py", "loops.py", "generate.py", "printed.py",
                      "lanes.py", "rosenbrock.py", "stiff_crossing.py", "columns.py", "expression_text.py")


def generator_digest() -> str:
    here = Path(__file__).resolve().parent
    digest = hashlib.sha256()
    for name in _GENERATOR_SOURCES:
        digest.update((here / name).read_bytes())
    digest.update((here.parent / "model" / "backlash.py").read_bytes())
    return digest.hexdigest()


def code_hash(system: FirstOrderSystem, options: LoopOptions) -> str:
    """SHA-256 of everything that determines the C: model equations, names, loop options, versions."""
    text = ExpressionText()
    description = {
        "codegen": CODEGEN_VERSION,
        "generator": generator_digest(),
        "casadi": ca.__version__,
        "name": system.name,
        "time": system.time.name,
        "states": [s.name for s in system.states],
        "rhs": [text.srepr(f) for f in system.rhs],
        "parameters": list(system.parameters),
        "period": text.srepr(system.period),
        "observed": list(system.observed),
        "options": asdict(options),
    }
    return hashlib.sha256(json.dumps(description, sort_keys=True).encode()).hexdigest()


def manifest(mf: ModelFunctions, digest: str) -> dict:
    s = mf.system
    text = ExpressionText().str
    return {
        "model": s.name,
        "hash": digest,
        "casadi_version": ca.__version__,
        "codegen_version": CODEGEN_VERSION,
        "options": asdict(mf.options),
        "time": s.time.name,
        "period": text(s.period),
        "states": [x.name for x in s.states],
        "observed": list(s.observed),
        "parameters": list(s.parameters),
        "equations": {f"d{x.name}/d{s.time.name}": text(f) for x, f in zip(s.states, s.rhs)},
        "tables": {str(k): text(v) for k, v in mf.split.tables},
        "constants": {str(k): text(v) for k, v in mf.split.constants},
        "functions": {name: str(f) for name, f in mf.functions.items()},
    }


@dataclass(frozen=True)
class GeneratedCode:
    directory: Path
    source: Path
    manifest: Path
    hash: str
    lanes: Path | None = None  # the lanes' C (:mod:`.lanes`), compiled only when lanes are asked for


def casadi_source(file_name: str, functions) -> str:
    """The C file ``file_name`` CasADi's code generator writes for ``functions`` (deterministic; without a header,
    no prefix), as text: generated into a private temporary folder by the generator's own prefix (the working
    directory is left alone, which another thread may be using) and read back."""
    gen = ca.CodeGenerator(file_name, {"with_header": False, "verbose": False, "prefix": ""})
    for f in functions:
        gen.add(f)
    with tempfile.TemporaryDirectory() as tmp:
        return Path(gen.generate(tmp + os.sep)).read_text()


def write_code(mf: ModelFunctions, directory: Path, digest: str) -> GeneratedCode:
    """Write ``<model>.c``, ``<model>_lanes.c`` and ``manifest.json`` into ``directory`` (atomically: no
    half-written files): CasADi's C, with the integration loops printed by :mod:`.printed`, and the lanes printed
    from the same C by :mod:`.lanes`."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    name = mf.system.name
    with tempfile.TemporaryDirectory(dir=directory) as tmp:
        text = casadi_source(source_file(name), [stand_in(f, pieces(mf, fname)) if fname in LOOP_NAMES else f
                                                 for fname, f in mf.functions.items()])
        source, lanes = Path(tmp) / source_file(name), Path(tmp) / lanes_file(name)
        lanes.write_text(lanes_source(mf))
        source.write_text(print_loops(text, mf))
        os.replace(lanes, directory / lanes.name)
        os.replace(source, directory / source.name)
    text = json.dumps(manifest(mf, digest), indent=2, sort_keys=True) + "\n"
    write_atomically(directory / "manifest.json", text)
    return GeneratedCode(directory, directory / source_file(name), directory / "manifest.json", digest,
                         directory / lanes_file(name))


