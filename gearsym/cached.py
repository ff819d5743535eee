"""A compiled model without its reduction: what a run needs, kept as JSON beside the compiled library.

Reducing a drivetrain takes a second or two of SymPy, and importing SymPy (and pint) most of another; a
command on a model whose library is cached needs neither. The first run of a model (a name or a file) with
given ``--set`` values writes two small files into the cache (``$GEARSYM_CACHE/models``):

* ``<model>-<key>.json``: the system's names, values, constraints and flags (:class:`SystemSummary`) and, for
  a model with physical values, the numbers that carry a spectrum run back to its units
  (:class:`~gearsym.physical.point.PointUnits`: no pint needed), under
  a key that hashes the model's file, the other model files it may import, gearsym's own source and the
  values: any change to one of them is another key, never a stale summary;
* ``<model>-<key>-<loops>.json``: for one structure of the loops (steps per period, crossings located), the
  code hash and the compiled library (:class:`BuildSummary`).

Later runs build the :class:`~gearsym.codegen.compiled.CompiledModel` from them, with a
:class:`SystemSummary` as its system, which loads (and reduces) the model only if something asks for what
it does not keep (a SymPy expression). A summary that is missing, unreadable, not ours or pointing at a
library that is gone is ignored and rewritten; files are written atomically. Only JSON is read.

A summary is trusted no more than the library: it is read as a private file
(:func:`~gearsym.files.sealed.read_sealed`), its content must match the seal written with it (a hash of the
content and the file's name, which hashes the model and values it is for), and what it says must match what
it describes: the library's record (:mod:`gearsym.codegen.trust`) must name the same model, code hash, states
and parameters. A summary that does not (edited: states swapped, values changed, another model's library) is
written again, and a warning says so.
"""
from __future__ import annotations

import hashlib
import json
import os
import sys
from collections.abc import Callable, Mapping
from dataclasses import asdict, dataclass, field, replace
from functools import lru_cache
from pathlib import Path

from .codegen.compiler import binary_key, cache_dir, compile_flags
from .codegen.library import library_describes, library_from_code, library_model, resolve_backend
from .codegen.loops import LoopOptions
from .codegen.step_choice import chosen
from .codegen.trust import check, differences
from .options import Integration
from .parameters import Constraint, ParameterChecks
from .physical.point import PointUnits
from .files.sealed import distrust, read_sealed, write_sealed
from .registry import model_file, models_dir
from .stability.recipe import CompiledLinearisation
from .stability.recipe import StaticRecipe

#: bump when what a summary holds changes
SUMMARY_FORMAT = 6


@dataclass(frozen=True, eq=False)
class SystemSummary(ParameterChecks):
    """The part of a :class:`~gearsym.system.FirstOrderSystem` a run reads, without SymPy; its symbolic part
    (equations, couplings, the period as an expression) comes from the full system (:attr:`full`), loaded on
    first use."""

    name: str
    title: str
    time_name: str
    state_names: tuple[str, ...]
    parameters: Mapping[str, float]
    initial: Mapping[str, float]
    coordinates: tuple[str, ...]
    descriptions: Mapping[str, str]
    constraints: Mapping[str, Constraint]
    autonomous: bool
    physical: bool  # the model has physical values (its results are also given in its units)
    load: Callable[[], object] = field(repr=False, default=None)  # the full system
    cycles: int = 1  # forcing periods in one period (a gear's revolution with shaft-order terms)
    fastest: float = 0.0  # the fastest linearised mode's rate and the forcing period at these values: the step's
    cycle: float = 0.0  # choice (codegen/step_choice.py) without the model
    #: the full system's contact_watches when each is numbers and parameters' names (what an orbit's contact is
    #: read from, without the reduction); None: from the full system
    watches: tuple[tuple[str, str, float | str, float | str], ...] | None = None

    @property
    def dimension(self) -> int:
        return len(self.state_names)

    @property
    def observed(self) -> tuple[str, ...]:
        return self.coordinates or self.state_names

    @property
    def initial_vector(self) -> tuple[float, ...]:
        return tuple(float(self.initial.get(s, 0.0)) for s in self.state_names)

    @property
    def full(self):
        """The full system (the model loaded and reduced: seconds, once)."""
        if "_full" not in self.__dict__:
            object.__setattr__(self, "_full", self.load())
        return self.__dict__["_full"]

    @property
    def time(self):
        """The time symbol (from the full system)."""
        return self.full.time

    @property
    def states(self):
        return self.full.states

    @property
    def rhs(self):
        return self.full.rhs

    @property
    def period(self):
        """The period as an expression (from the full system)."""
        return self.full.period

    @property
    def contact_watches(self) -> tuple:
        """The meshes an orbit's contact regime is read on (see the full system's ``contact_watches``)."""
        return self.full.contact_watches if self.watches is None else self.watches

    @property
    def couplings(self):
        """The meshes and shafts the reduction handed on (from the full system)."""
        return self.full.couplings

    def as_dict(self) -> dict:
        return {"name": self.name, "title": self.title, "time_name": self.time_name,
                "state_names": list(self.state_names), "parameters": dict(self.parameters),
                "initial": dict(self.initial), "coordinates": list(self.coordinates),
                "descriptions": dict(self.descriptions),
                "constraints": {k: c.as_list() for k, c in self.constraints.items()},
                "autonomous": self.autonomous, "physical": self.physical, "cycles": self.cycles,
                "fastest": self.fastest, "cycle": self.cycle,
                "watches": None if self.watches is None else [list(w) for w in self.watches]}

    @classmethod
    def from_dict(cls, d: dict, load: Callable[[], object]) -> "SystemSummary":
        return cls(str(d["name"]), str(d["title"]), str(d["time_name"]), tuple(map(str, d["state_names"])),
                   {str(k): float(v) for k, v in d["parameters"].items()},
                   {str(k): float(v) for k, v in d["initial"].items()}, tuple(map(str, d["coordinates"])),
                   {str(k): str(v) for k, v in d["descriptions"].items()},
                   {str(k): Constraint.from_list(c) for k, c in d["constraints"].items()},
                   bool(d["autonomous"]), bool(d["physical"]), load, int(d["cycles"]), float(d["fastest"]),
                   float(d["cycle"]), _watches(d["watches"]))

    @classmethod
    def of(cls, system, physical: bool, fastest: float = 0.0) -> "SystemSummary":
        """The summary of ``system`` (``fastest``: its fastest linearised mode's rate, for the step's choice)."""
        return cls(system.name, system.title, system.time.name, system.state_names, dict(system.parameters),
                   dict(system.initial), tuple(system.coordinates), dict(system.descriptions),
                   dict(system.constraints), system.autonomous, physical, lambda: system, system.cycles,
                   fastest, system.cycle_at(),
                   system.watches if isinstance(system, SystemSummary) else _plain_watches(system.contact_watches))


def _plain_watches(watches) -> tuple | None:
    """``watches`` if each backlash and offset is a number or a parameter's name (what a summary can hold), else
    None."""
    plain = all(isinstance(v, (float, str)) for w in watches for v in w[2:])
    return tuple(tuple(w) for w in watches) if plain else None


def _watches(stored) -> tuple | None:
    if stored is None:
        return None
    return tuple((str(n), str(c), *(v if isinstance(v, str) else float(v) for v in (b, o))) for n, c, b, o in stored)


@dataclass(frozen=True)
class BuildSummary:
    """What the cache keeps of one build of a model (``<model>-<key>-<loops>.json``): its code hash, the compiled
    library, the parameters in its tables of time, and those tables as text."""

    hash: str
    library: Path
    timed_parameters: frozenset[str]
    table_texts: tuple[str, ...]

    @classmethod
    def of(cls, compiled) -> "BuildSummary":
        return cls(compiled.hash, Path(compiled.library), frozenset(compiled.timed_parameters),
                   tuple(compiled.table_texts))

    def as_dict(self) -> dict:
        return {"hash": self.hash, "library": str(self.library), "timed_parameters": sorted(self.timed_parameters),
                "table_texts": list(self.table_texts)}

    @classmethod
    def from_dict(cls, d: dict) -> "BuildSummary":
        return cls(str(d["hash"]), Path(d["library"]), frozenset(d["timed_parameters"]),
                   tuple(str(t) for t in d["table_texts"]))

    @property
    def in_own_cache(self) -> bool:
        """Whether the library is one of the cache's own (no other is loaded)."""
        return self.library.parent == cache_dir("lib") and not self.library.name.startswith(".")


@lru_cache(maxsize=None)
def _source_digest(folder: Path) -> str:
    """Every Python file below ``folder`` (gearsym's own code: whatever derives a system) by its size and time of
    change, as Python's own bytecode cache tells an edited module (reading them all would cost start-up time)."""
    digest = hashlib.sha256()
    for parts, size, changed in sorted(_python_files(folder)):  # (in the order of the paths' parts, as Paths sort)
        digest.update(f"{'/'.join(parts)}\0{size}\0{changed}\n".encode())
    return digest.hexdigest()


def _python_files(folder, parts: tuple[str, ...] = ()):
    """(path parts below ``folder``, size, time of change) of every ``*.py`` file there, as ``Path.rglob`` finds
    them, read with ``os.scandir`` (half the time of making a Path of each)."""
    with os.scandir(folder) as entries:
        for entry in entries:
            if entry.is_dir():
                yield from _python_files(entry.path, (*parts, entry.name))
            elif entry.name.endswith(".py"):
                stat = entry.stat()
                yield (*parts, entry.name), stat.st_size, stat.st_mtime_ns


def _model_files(folders: tuple[Path, ...]) -> dict[str, str]:
    """The model files in ``folders`` by their content's hash (a model imports another; read every time: a model
    file edited in a long-lived process must be noticed)."""
    return {str(f): _content(f) for folder in folders for f in sorted(folder.glob("*.py"))}


def _content(path: Path) -> str:
    """The hash of a model file's bytes; what else stands at a ``*.py`` name (a folder, a broken symlink: no
    model, but it may become one) by its kind."""
    try:
        return hashlib.sha256(path.read_bytes()).hexdigest() if path.is_file() else f"not a file: {_kind(path)}"
    except OSError as exc:
        return f"unreadable: {exc.strerror}"


def _kind(path: Path) -> str:
    return "a folder" if path.is_dir() else "a broken symlink" if path.is_symlink() else "not a regular file"


def system_key(path: Path, values: Mapping[str, object]) -> str:
    """What the reduction of the model in ``path`` with ``values`` depends on, hashed: the model file, the
    model files beside it and in the models folder (a model imports another), gearsym's source, the values."""
    files = _model_files(tuple(sorted({path.parent, models_dir().resolve()})))
    description = {"format": SUMMARY_FORMAT, "model": str(path), "files": files,
                   "gearsym": _source_digest(Path(__file__).resolve().parent),
                   "python": sys.version, "values": {k: repr(v) for k, v in sorted(values.items())}}
    return hashlib.sha256(json.dumps(description, sort_keys=True).encode()).hexdigest()[:24]


def loops_key(loops: LoopOptions) -> str:
    """The loops' structure and where the library must run (the compiler and its flags name the library)."""
    flags = compile_flags()
    description = {"loops": asdict(loops), "binary": binary_key(flags), "cc": os.environ.get("CC", "")}
    return hashlib.sha256(json.dumps(description, sort_keys=True).encode()).hexdigest()[:12]


def summary_path(name: str, key: str) -> Path:
    return cache_dir("models") / f"{name}-{key}.json"


def read_json(path: Path) -> dict | None:
    """A summary this module wrote, or None (:func:`~gearsym.files.sealed.read_sealed`)."""
    return read_sealed(path, SUMMARY_FORMAT, _WHAT)


def write_json(path: Path, data: dict) -> None:
    write_sealed(path, data, SUMMARY_FORMAT)


#: how a warning names a summary not used
_WHAT = "cached summary"


@dataclass(frozen=True)
class CacheSlot:
    """Where the start-up cache keeps the model ``ref`` with given values (its file's name and the key that hashes
    what its reduction depends on; ``name`` None for a model that is no file, which the cache does not keep), and
    what the slot holds: the system's summary as read (``system``: None when there is none, or none to trust) and,
    for a model with physical values, its :class:`~gearsym.physical.point.PointUnits`. Read once per run."""

    name: str | None = None
    key: str = ""
    system: Mapping | None = None
    units: PointUnits | None = None

    @property
    def physical(self) -> bool | None:
        """Whether the model has physical values, as its summary says (None: no summary)."""
        return None if self.system is None else bool(self.system["physical"])

    def keeps(self, options: Integration) -> bool:
        """Whether a model compiled with ``options`` is kept here (a model in a file, compiled to a library)."""
        return self.name is not None and resolve_backend(options.backend) == "compiled"

    def summary(self, full: Callable[[], object]) -> SystemSummary | None:
        """The system's summary the slot holds (see :func:`read_summary`), or None."""
        return read_summary(self.system, full)


def cache_slot(ref, values: Mapping[str, object]) -> CacheSlot:
    """The slot of the model ``ref`` (a name or a file) with ``values``, and the summary it holds, read once."""
    path = model_file(ref) if isinstance(ref, str) else None
    if path is None:
        return CacheSlot()
    key = system_key(path, values)
    data = read_json(summary_path(path.stem, key))
    try:
        system = data["system"]
        physical = data["physical"] if system["physical"] else None
        return CacheSlot(path.stem, key, system, PointUnits.from_dict(physical) if physical else None)
    except (KeyError, TypeError, ValueError, AttributeError):
        return CacheSlot(path.stem, key)


def cached_compiled(slot: CacheSlot, options: Integration, full: Callable[[], object], verbose: bool = False):
    """The compiled model the slot's summaries and library give for ``options`` (``full``: the full system, loaded
    only if a caller asks for its symbolic part), or None: no summary, no library for these loops, a backend other
    than the compiled one, or summaries not to trust. ``verbose``: say so when the library is compiled again."""
    if not slot.keeps(options):
        return None
    if options.integrator == "auto":  # (chosen from the model's fastest mode, which its summary keeps)
        try:
            options = chosen(options, float(slot.system["fastest"]), float(slot.system["cycle"]))
        except (KeyError, TypeError, ValueError):
            return None
    build_file = summary_path(slot.name, f"{slot.key}-{loops_key(LoopOptions.of(options))}")
    return _from_cache(slot.system, build_file, options, full, verbose)


def keep_compiled(slot: CacheSlot, compiled, units: PointUnits | None) -> None:
    """``compiled``'s summaries written into its slot (the build's under the loops it was compiled with), with
    the ``units`` of a model with physical values."""
    system_file = summary_path(slot.name, slot.key)
    build_file = summary_path(slot.name, f"{slot.key}-{loops_key(LoopOptions.of(compiled.integration))}")
    summary = SystemSummary.of(compiled.system, units is not None, compiled.fastest)
    write_json(system_file, {"system": summary.as_dict(), "physical": units and units.as_dict()})
    write_json(build_file, BuildSummary.of(compiled).as_dict())


def read_summary(system: Mapping | None, full: Callable[[], object]) -> SystemSummary | None:
    """The :class:`SystemSummary` of a system's summary as read from the cache (``full``: the full system, loaded
    only if a caller asks for its symbolic part), or None: no summary, or none that reads as one."""
    try:
        return SystemSummary.from_dict(system, full)
    except (KeyError, TypeError, ValueError, AttributeError):
        return None


def read_build(path: Path) -> BuildSummary | None:
    """The :class:`BuildSummary` in ``path``, or None: none, or none that reads as one."""
    try:
        return BuildSummary.from_dict(read_json(path))
    except (KeyError, TypeError, ValueError, AttributeError):
        return None


def _from_cache(system: Mapping | None, build_file: Path, options: Integration, full: Callable[[], object],
                verbose: bool = False):
    """The compiled model of a system's summary as read (``system``) and the build summary in ``build_file``, or
    None: either missing or unreadable, a library not of our own cache and no verified C to compile it from, or
    summaries that do not describe the library they point at (edited: said here). A library gone or not as
    compiled (damaged, a symlink: said by the compiler) is compiled again from the C that vouches for the same
    code, states and parameters (:func:`~gearsym.codegen.library.library_from_code`), without the model."""
    summary = read_summary(system, full)
    build = read_build(build_file)
    if summary is None or build is None or not build.in_own_cache or summary.cycles < 1:
        return None
    if not build.timed_parameters <= set(summary.parameters):
        why = "it names parameters its model does not have"
    else:
        verdict = check(build.library)
        if verdict.data is None:
            return _compiled_again(summary, build, build_file, options, verbose)
        why = differences(verdict.describes, library_describes(summary, build.hash))
        if why is None:  # (the summaries describe the library they point at)
            return library_model(summary, build.hash, build.library, options, build.timed_parameters,
                                 build.table_texts, summary.fastest)
        why = f"{build.library.name}, the library it points at, does not match it: {why}"
    distrust(build_file, why, _WHAT)  # (edited: said once, and the summaries are written again)
    return None


def _compiled_again(summary: SystemSummary, build: BuildSummary, build_file: Path, options: Integration,
                    verbose: bool):
    """The compiled model of ``build`` with its library compiled again from its C (the compiler says why the one
    in the cache is not used), the build summary written again if the library's name changed; or None: no C that
    vouches for it (the model is loaded and its C generated)."""
    announce = (lambda message: print(f"gearsym: {message}", file=sys.stderr, flush=True)) if verbose else None
    library = library_from_code(summary, build.hash, announce)
    if library is None:
        return None
    if library != build.library:
        write_json(build_file, replace(build, library=library).as_dict())
    return library_model(summary, build.hash, library, options, build.timed_parameters, build.table_texts,
                         summary.fastest)


def load_linearisation(ref: str, values: Mapping[str, object], options: Integration, *,
                       derive: Callable[[], CompiledLinearisation], verbose: bool = False) -> CompiledLinearisation:
    """The compiled linearisation about its static state of the model ``ref`` with ``values`` (a stability
    chart's): from the cache as :func:`keep_compiled` keeps a model (its summaries beside the linear system's
    library, with the static recipe and the model's own parameters), else ``derive()`` (the model loaded,
    linearised and compiled) and the summaries written."""
    path = model_file(ref) if isinstance(ref, str) else None
    if path is None or resolve_backend(options.backend) != "compiled":
        return derive()
    options = replace(options, locate_crossings=True)  # (the linear system's tables are factored)
    key, loops = system_key(path, values), LoopOptions.of(options)
    name = f"{path.stem}_linearised"
    system_file = summary_path(name, key)
    build_file = summary_path(name, f"{key}-{loops_key(loops)}")
    data = read_json(system_file)
    compiled = _from_cache(data.get("system") if data is not None else None, build_file, options,
                           lambda: derive().model.system, verbose)
    if compiled is not None:
        try:
            about = data["linearisation"]
            return CompiledLinearisation(compiled, StaticRecipe.from_dict(about["static"]),
                                         tuple(map(str, about["anchors"])), str(about["base"]),
                                         {str(k): float(v) for k, v in about["parameters"].items()},
                                         bool(about["physical"]))
        except (KeyError, TypeError, ValueError, AttributeError):
            pass
    lin = derive()
    write_json(system_file, {"system": SystemSummary.of(lin.model.system, False).as_dict(), "physical": None,
                             "linearisation": {"static": lin.recipe.as_dict(), "anchors": list(lin.anchors),
                                               "base": lin.base, "parameters": dict(lin.base_parameters),
                                               "physical": lin.physical}})
    write_json(build_file, BuildSummary.of(lin.model).as_dict())
    return lin


def load_static_recipe(ref: str, values: Mapping[str, object], *, derive: Callable[[], StaticRecipe]) -> StaticRecipe:
    """The static problem of the model ``ref`` with ``values`` (the start of a chart about the periodic orbits):
    from the cache, else ``derive()`` and kept."""
    path = model_file(ref) if isinstance(ref, str) else None
    if path is None:
        return derive()
    file = summary_path(f"{path.stem}_static", system_key(path, values))
    data = read_json(file)
    if data is not None:
        try:
            return StaticRecipe.from_dict(data["static"])
        except (KeyError, TypeError, ValueError, AttributeError):
            pass
    recipe = derive()
    write_json(file, {"static": recipe.as_dict()})
    return recipe
