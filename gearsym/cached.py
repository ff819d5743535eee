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
  code hash and the compiled library (:class:`~gearsym.codegen.kept.BuildSummary`: kept, found again for a run's
  options and trusted by :mod:`gearsym.codegen.kept`).

A run with new plain numbers for some of the system's parameters (``--set omega=0.82``) finds its entry made from
the entry of the same model without them (:mod:`gearsym.codegen.derived_summary`: the values replaced, the step's
choice recomputed from the model's library), where there is one.

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
import math
import os
import sys
from collections.abc import Callable, Mapping
from dataclasses import field, replace
from functools import lru_cache
from pathlib import Path

from .records import record_class
from .codegen.kept import (SUMMARY_FORMAT, BuildSummary, build_path, found_build, found_over, keep_model, kept_model,
                           read_build, read_builds, read_json, summary_path, write_json)
from .codegen.derived_summary import derived_entry
from .codegen.system_summary import SystemSummary, read_summary
from .codegen.library import resolve_backend
from .options import Integration
from .physical.point import PointUnits
from .registry import model_file, models_dir
from .stability.recipe import CompiledLinearisation
from .stability.recipe import StaticRecipe

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
    return system_keys(path, values)[0]


def system_keys(path: Path, *values: Mapping[str, object]) -> tuple[str, ...]:
    """:func:`system_key` of the model in ``path`` with each of ``values``, its files read and hashed once."""
    files = _model_files(tuple(sorted({path.parent, models_dir().resolve()})))
    described = {"format": SUMMARY_FORMAT, "model": str(path), "files": files,
                 "gearsym": _source_digest(Path(__file__).resolve().parent), "python": sys.version}
    return tuple(hashlib.sha256(json.dumps({**described, "values": {k: repr(v) for k, v in sorted(each.items())}},
                                           sort_keys=True).encode()).hexdigest()[:24] for each in values)


@record_class
class CacheSlot:
    """Where the start-up cache keeps the model ``ref`` with given values (its file's name and the key that hashes
    what its reduction depends on; ``name`` None for a model that is no file, which the cache does not keep), and
    what the slot holds: the system's summary as read (``system``: None when there is none, or none to trust),
    for a model with physical values its :class:`~gearsym.physical.point.PointUnits`, and the builds kept of it
    (``builds``: each :class:`~gearsym.codegen.kept.BuildSummary` by its file, or why the file is not to be
    trusted; one this process keeps is added). Read once per run."""

    name: str | None = None
    key: str = ""
    system: Mapping | None = None
    units: PointUnits | None = None
    builds: dict[Path, BuildSummary | str] = field(default_factory=dict)

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

    def compiled_model(self, options: Integration, ends: list[dict[str, float]], making: "Making"):
        """The compiled model with ``options``: the one the slot keeps (:mod:`gearsym.codegen.kept`), else
        ``making``'s, kept here. ``ends``: the corners of the engine's axes a sweep runs over (none for one point);
        with ``integrator="auto"`` the step is chosen for the fastest of them: from the Jacobian and period of a
        library the slot keeps for the model (no SymPy, no reduction), else from the full system
        (``making.choose_over``)."""
        keeps = self.keeps(options)  # (the step's choice keeps the backend)
        summary = read_summary(self.system, making.load_system) if self.name is not None else None
        auto = options.integrator == "auto" and bool(ends)
        found = (found_over(self.name, self.key, summary, self.builds, options, ends) if auto and summary is not None
                 else None)
        if found is None:
            options = making.choose_over(options, ends) if auto else options
            found = found_build(self.name, self.key, summary, self.builds, options) if summary is not None else None
        if found is None:
            system = making.load_system()
            if making.before is not None:
                making.before(system)
            found = making.compile_system(system, options)
            if keeps:
                self.builds.update(keep_model(self.name, self.key, found, making.kept_units()))
        return found


@record_class
class Making:
    """How a model the cache does not hold is made, given by the caller that opens it (the face's verbs, which load
    SymPy and the code generator on first use): ``load_system()`` the full system, ``choose_over(options, ends)``
    the step chosen from it for the fastest of a sweep's ``ends``, ``compile_system(system, options)`` the
    compiler, ``kept_units()`` the point units a model with physical values is kept with, and ``before(system)``
    the run's checks of its request against the loaded system (made before the compiler's seconds)."""

    load_system: Callable[[], object]
    choose_over: Callable[[Integration, list], Integration]
    compile_system: Callable[[object, Integration], object]
    kept_units: Callable[[], PointUnits | None]
    before: Callable[[object], object] | None = None


def plain_values(values: Mapping[str, object]) -> dict[str, float]:
    """The values of ``values`` that are plain finite numbers (what a derived entry may differ by)."""
    return {name: float(v) for name, v in values.items()
            if isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)}


def cache_slot(ref, values: Mapping[str, object]) -> CacheSlot:
    """The slot of the model ``ref`` (a name or a file) with ``values``, and the summary it holds, read once."""
    path = model_file(ref) if isinstance(ref, str) else None
    if path is None:
        return CacheSlot()
    plain = plain_values(values)  # (new plain values: the entry is derived from the one without them)
    without = {k: v for k, v in values.items() if k not in plain}
    key, base_key = system_keys(path, values, without) if plain else (system_key(path, values), None)
    data = read_json(summary_path(path.stem, key))
    if data is None and plain:
        data = derived_entry(path, base_key, key, plain)
    try:
        system = data["system"]
        physical = data["physical"] if system["physical"] else None
        units = PointUnits.from_dict(physical) if physical else None
    except (KeyError, TypeError, ValueError, AttributeError):
        return CacheSlot(path.stem, key)
    return CacheSlot(path.stem, key, system, units, read_builds(path.stem, key))


def load_linearisation(ref: str, values: Mapping[str, object], options: Integration, *,
                       derive: Callable[[], CompiledLinearisation], verbose: bool = False) -> CompiledLinearisation:
    """The compiled linearisation about its static state of the model ``ref`` with ``values`` (a stability
    chart's): from the cache as :func:`~gearsym.codegen.kept.keep_model` keeps a model (its summaries beside the
    linear system's library, with the static recipe and the model's own parameters), else ``derive()`` (the model
    loaded, linearised and compiled) and the summaries written."""
    path = model_file(ref) if isinstance(ref, str) else None
    if path is None or resolve_backend(options.backend) != "compiled":
        return derive()
    options = replace(options, locate_crossings=True)  # (the linear system's tables are factored)
    key = system_key(path, values)
    name = f"{path.stem}_linearised"
    system_file = summary_path(name, key)
    build_file = build_path(name, key, options)
    data = read_json(system_file)
    compiled = kept_model(read_summary(data.get("system") if data is not None else None,
                                       lambda: derive().model.system), read_build(build_file), build_file, options)
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
