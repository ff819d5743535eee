"""Building an FMU from a system: the engine's C (the committed ``generated/<model>/`` C when it is this model's,
else generated into the cache as for any run), the FMU's own functions and wrapper, the binary of this
platform compiled from them, the model description, all in one deterministic archive.

The binary is compiled for any CPU of the platform (``-O2``, no ``-march=native`` and no fused multiply-add
contraction, unlike the engine's own cached libraries): an FMU travels. The same sources compile on another
platform from ``sources/`` (its ``buildDescription.xml`` lists them).
"""
from __future__ import annotations

import hashlib
import json
import platform
import shlex
import struct
import subprocess
import tempfile
import time
from dataclasses import asdict, dataclass
from importlib import resources
from pathlib import Path

from ..files.atomic import writing
from ..files.private import CACHE_ADVICE
from ..codegen.code_files import cached_code_directory, code_directory, read_manifest
from ..codegen.compiler import CompilerError, compilers_looked_for, find_compiler, INSTALL_HINT
from ..codegen.functions import build_functions
from ..codegen.generate import code_hash, write_code
from ..codegen.fastest_mode import fastest_rate
from ..codegen.loops import LoopOptions
from ..codegen.step_choice import explicit
from ..codegen.surfaces import switching_surfaces
from ..codegen.time_tables import split_rhs
from ..errors import GearsymError, ModelError
from ..options import Integration
from ..system import FirstOrderSystem
from .archive import write_archive
from .description import build_description, model_description
from .frame import Frame
from .functions import SOURCE as FUNCTIONS, fmu_functions, indicators, write_functions
from .variables import Layout, layout
from .wrapper import GUID_MARK, HEADER, WRAPPER, model_header, wrapper_source

#: the FMI 2.0 headers shipped in every FMU's sources (package data, see headers/README.md)
FMI_HEADERS = ("fmi2FunctionTypes.h", "fmi2Functions.h", "fmi2TypesPlatform.h")
#: how the binary is compiled (portable: see the module's docstring); the wrapper and the FMU's functions
FLAGS = ("-O2", "-fPIC", "-shared", "-fvisibility=hidden", "-ffp-contract=off", "-std=gnu99")
#: forcing periods of the default experiment
EXPERIMENT_PERIODS = 20


@dataclass(frozen=True)
class ExportedFmu:
    """What :func:`build_fmu` wrote."""

    path: Path
    model: str
    guid: str
    size: int  # bytes of the archive
    seconds: float  # to build it all
    compile_seconds: float  # of which compiling the binary
    physical: bool
    variables: int
    event_indicators: int

    def as_dict(self) -> dict:
        return {**asdict(self), "path": str(self.path)}


def build_fmu(system: FirstOrderSystem, path: Path, options: Integration = Integration(), frame: Frame = Frame(),
              ) -> ExportedFmu:
    """Write the FMU of ``system`` (its values the start values) to ``path``; ``options``: the engine's step
    (steps per period and located crossings: the co-simulation step's C); ``frame``: how its variables stand to
    the engine's (SI for a physical model, :mod:`.physical`)."""
    start = time.perf_counter()
    identifier = system.name
    if not identifier.isidentifier():
        raise ModelError("an FMU's model identifier must be a C identifier (letters, digits, _)", identifier)
    folder = binary_folder()
    # the co-simulation step is RK4's, at as many steps as resolve the fastest mode (no stiff FMU yet)
    options = explicit(options, fastest_rate(system), system.cycle_at())
    loops = LoopOptions.of(options, system.cycles)
    if loops.block(system.dimension) != 1:
        raise GearsymError(f"{identifier}: the co-simulation step needs the loops' one-step blocks")
    engine = _engine_source(system, loops)
    split = split_rhs(system, factored=loops.locate_crossings)
    surfaces = _surfaces(system, loops)
    lay = layout(system, frame, indicators(system, surfaces))
    with tempfile.TemporaryDirectory(prefix="gearsym-fmu-") as tmp:
        tmp = Path(tmp)
        functions_c = write_functions(fmu_functions(lay, split), tmp).read_bytes()
        wrapper = wrapper_source()
        header = model_header(lay, engine.name, len(split.constants) + 1, len(split.tables),
                              steps_per_period=loops.steps_per_period)
        guid = _guid(engine.read_bytes(), functions_c, wrapper + header, lay)
        header = header.replace(GUID_MARK, guid)
        sources = {name: resources.files(__package__).joinpath("headers", name).read_bytes() for name in FMI_HEADERS}
        sources |= {WRAPPER: wrapper.encode(), HEADER: header.encode(), engine.name: engine.read_bytes(),
                    FUNCTIONS: functions_c}
        compiled = (WRAPPER, FUNCTIONS)
        for name, data in sources.items():
            (tmp / name).write_bytes(data)
        binary, compile_seconds = _compile(tmp, identifier, compiled)
        files = {f"sources/{name}": data for name, data in sources.items()}
        files["sources/buildDescription.xml"] = build_description(identifier, compiled).encode()
        files["modelDescription.xml"] = model_description(lay, guid, compiled, _experiment(lay, loops)).encode()
        files[f"binaries/{folder}/{binary.name}"] = binary.read_bytes()
    path = write_archive(Path(path), files)
    return ExportedFmu(path, identifier, guid, path.stat().st_size, time.perf_counter() - start, compile_seconds,
                       frame.physical, len(lay.variables), len(lay.indicators))


def binary_folder() -> str:
    """This platform's folder under ``binaries/`` (FMI 2.0's names)."""
    bits = 8 * struct.calcsize("P")
    system = {"Linux": "linux", "Darwin": "darwin", "Windows": "win"}.get(platform.system())
    if system is None or (system == "linux" and platform.machine() not in ("x86_64", "AMD64", "i686", "i386")):
        raise GearsymError(f"FMI 2.0 names no binaries/ folder for {platform.system()} on {platform.machine()}; "
                           "export on Linux, macOS or Windows (x86), the sources inside build it elsewhere")
    return f"{system}{bits}"


def _library_suffix() -> str:
    return {"Darwin": ".dylib", "Windows": ".dll"}.get(platform.system(), ".so")


def _engine_source(system: FirstOrderSystem, loops: LoopOptions) -> Path:
    """The engine's C of ``system``: the committed or cached one of its code hash, generated if missing."""
    digest = code_hash(system, loops)
    directory = code_directory(system.name, digest)
    source = directory / f"{system.name}.c"
    if not ((read_manifest(directory) or {}).get("hash") == digest and source.is_file()):
        directory = cached_code_directory(system.name, digest)
        with writing(directory, CACHE_ADVICE):
            write_code(build_functions(system, loops), directory, digest)
        source = directory / f"{system.name}.c"
    return source


def _surfaces(system: FirstOrderSystem, loops: LoopOptions):
    """The switching surfaces the engine locates (none for the paper's plain scheme on a model that switches
    otherwise too: its event indicators are then the meshes' alone)."""
    try:
        return switching_surfaces(system)
    except ModelError:
        if loops.locate_crossings:
            raise
        return ()


def _guid(engine: bytes, functions: bytes, wrapper: str, lay: Layout) -> str:
    """The FMU's GUID: a hash of everything that makes its behaviour (the C, the variables, the frame): an FMU
    exported again from the same model has the same one, any change another."""
    digest = hashlib.sha256()
    for part in (engine, functions, wrapper.encode(), json.dumps(_described(lay), sort_keys=True).encode()):
        digest.update(hashlib.sha256(part).digest())
    h = digest.hexdigest()
    return "{" + f"{h[:8]}-{h[8:12]}-{h[12:16]}-{h[16:20]}-{h[20:32]}" + "}"


def _described(lay: Layout) -> dict:
    f = lay.frame
    return {"variables": [[v.name, v.type, v.reference, v.causality, v.variability, v.start,
                           v.unit.name if v.unit else None] for v in lay.variables],
            "frame": [f.physical, f.time_unit, f.length_unit, f.omega, sorted(f.mesh_stiffness.items()),
                      sorted(f.scales.items()), sorted(f.mesh_damping.items()),
                      sorted(f.kinds.items()), sorted(lay.engine_base.items()),
                      [[p.name, [[t.engine, t.exponent, t.reference] for t in p.terms]] for p in lay.parameters]],
            "indicators": [str(e) for e in lay.indicators]}


def _experiment(lay: Layout, loops: LoopOptions) -> tuple[float, float, float]:
    """Start, stop and step of the default experiment: EXPERIMENT_PERIODS forcing periods (mesh periods of the
    first mesh), the engine's step (as many per forcing period as resolve the fastest mode: stable)."""
    cycle = lay.system.cycle_at()
    frame = lay.frame
    if frame.physical:  # seconds: tau runs at omega / T
        cycle *= frame.time_unit / lay.engine_base[frame.omega]
    return 0.0, EXPERIMENT_PERIODS * cycle, cycle / (loops.steps_per_period // lay.system.cycles)


def _compile(folder: Path, identifier: str, sources: tuple[str, ...]) -> tuple[Path, float]:
    """The binary of ``sources`` in ``folder`` (relative names, compiled there: no path of this machine in it)."""
    cc = find_compiler()
    if cc is None:
        raise CompilerError(f"no C compiler found (looked for {compilers_looked_for()}); an FMU carries a compiled "
                            f"binary. {INSTALL_HINT}")
    target = f"{identifier}{_library_suffix()}"
    command = [*shlex.split(cc), *FLAGS, "-I.", "-o", target, *sources, "-lm"]
    start = time.perf_counter()
    try:
        done = subprocess.run(command, cwd=folder, capture_output=True, text=True)
    except OSError as exc:
        raise CompilerError(f"could not run the C compiler {cc!r}: {exc}. Set $CC to a working compiler.") from None
    if done.returncode != 0:
        raise CompilerError(f"compiling the FMU of {identifier} failed ({' '.join(command)}):\n"
                            f"{done.stderr.strip()[-2000:]}")
    return folder / target, time.perf_counter() - start
