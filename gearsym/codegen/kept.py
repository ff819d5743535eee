"""A model's builds kept in the start-up cache, found again for a run's options without the model's reduction.

Beside the system's summary (:mod:`gearsym.cached`), the cache keeps one small file per structure of the loops a
model was compiled with (``<model>-<key>-<loops>.json``): the code hash, the compiled library, the parameters in
its tables of time and those tables as text (:class:`BuildSummary`). A model's builds are read once, with its
system's summary (:func:`read_builds`, by the start-up cache's slot). A build is found for the options a run asks
(the step chosen from the fastest linearised mode the system's summary keeps, or for a sweep's fastest point from a
library of the model kept already) and trusted no more than its library: the summary is a sealed private file
(:func:`~gearsym.files.sealed.read_sealed`), and the library's record (:mod:`.trust`) must name the same model, code
hash, states and parameters as the system's summary; a build that does not (edited: states swapped, another
model's library) is said once in a warning and written again. The library is loaded into this process's one table
(:mod:`.loaded`). Only JSON is read; nothing here needs SymPy.
"""
from __future__ import annotations

import hashlib
import json
import os
from dataclasses import asdict
from pathlib import Path

from ..records import record_class
from ..files.sealed import distrust, read_sealed, unsealed, write_sealed
from ..options import Integration
from .compiler import binary_key, cache_dir, compile_flags
from .library import library_describes, library_from_code, library_model, resolve_backend
from .loops import LoopOptions
from .mode_rates import chosen_by_compiled
from .step_choice import choices_from, chosen
from .system_summary import SystemSummary
from .trust import check, differences

#: bump when what a summary (the system's or a build's) holds changes
SUMMARY_FORMAT = 6
#: how a warning names a summary not used
WHAT = "cached summary"


@record_class
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


def loops_key(loops: LoopOptions) -> str:
    """The loops' structure and where the library must run (the compiler and its flags name the library)."""
    flags = compile_flags()
    description = {"loops": asdict(loops), "binary": binary_key(flags), "cc": os.environ.get("CC", "")}
    return hashlib.sha256(json.dumps(description, sort_keys=True).encode()).hexdigest()[:12]


def summary_path(name: str, key: str) -> Path:
    return cache_dir("models") / f"{name}-{key}.json"


def build_path(name: str, key: str, options: Integration) -> Path:
    """Where the build of the model ``name`` with the values of ``key``, compiled with ``options``, is kept."""
    return summary_path(name, f"{key}-{loops_key(LoopOptions.of(options))}")


def read_json(path: Path) -> dict | None:
    """A summary the cache wrote, or None (:func:`~gearsym.files.sealed.read_sealed`)."""
    return read_sealed(path, SUMMARY_FORMAT, WHAT)


def write_json(path: Path, data: dict) -> None:
    write_sealed(path, data, SUMMARY_FORMAT)


def read_build(path: Path) -> BuildSummary | None:
    """The :class:`BuildSummary` in ``path``, or None: none, or none that reads as one (one not to be trusted is
    said in a warning)."""
    return _build(read_json(path))


def read_builds(name: str, key: str) -> dict[Path, BuildSummary | str]:
    """Every build the cache keeps of the model ``name`` with the values of ``key``, by its file (:func:`build_path`):
    read once, with the system's summary, for whatever options a run then asks; for a file not to be trusted
    (edited), why not: said by :func:`kept_model` if a run asks for its options (as when it is read)."""
    folder = cache_dir("models")
    prefix = f"{name}-{key}-"
    with os.scandir(folder) as entries:
        files = sorted(e.name for e in entries if e.name.startswith(prefix) and e.name.endswith(".json"))
    builds = {}
    for file in files:
        record = unsealed(folder / file, SUMMARY_FORMAT)
        build = record if isinstance(record, str) else _build(record)
        if build is not None:
            builds[folder / file] = build
    return builds


def _build(record: dict | None) -> BuildSummary | None:
    try:
        return BuildSummary.from_dict(record)
    except (KeyError, TypeError, ValueError, AttributeError):
        return None


def found_over(name: str, key: str, summary, builds: dict[Path, BuildSummary | str], options: Integration,
               ends: list[dict[str, float]]):
    """The compiled model of a sweep over ``ends`` (the corners of its axes) from the cache alone, or None: the step
    chosen as the full system would choose it, from the Jacobian and period of any library the cache keeps for the
    model (the one of its own values, or one a sweep over faster points chose: the same functions whatever the
    loops); ``summary``: the system's (:class:`~.system_summary.SystemSummary`), ``builds``: the model's
    (:func:`read_builds`)."""
    choices = choices_from(options, summary.fastest, summary.cycle)
    libraries = (found_build(name, key, summary, builds, o) for o in choices)
    some = next((compiled for compiled in libraries if compiled is not None), None)
    chosen_here = None if some is None else chosen_by_compiled(options, some, ends)
    return None if chosen_here is None else found_build(name, key, summary, builds, chosen_here)


def found_build(name: str, key: str, summary, builds: dict[Path, BuildSummary | str], options: Integration):
    """The compiled model the cache keeps for ``options`` of the model ``name`` with the values of ``key`` (its
    system's ``summary``, its ``builds`` as read: :func:`read_builds`), or None: no build for these loops, a backend
    other than the compiled one, or a build not to trust."""
    if resolve_backend(options.backend) != "compiled":
        return None
    if options.integrator == "auto":  # (chosen from the model's fastest mode, which its summary keeps)
        options = chosen(options, summary.fastest, summary.cycle)
    build_file = build_path(name, key, options)
    return kept_model(summary, builds.get(build_file), build_file, options)


def kept_model(summary, build: BuildSummary | str | None, build_file: Path, options: Integration):
    """The compiled model of a system's ``summary`` and its ``build`` (as read from ``build_file``: see
    :func:`read_builds`), or None: either missing or unreadable, a library not of our own cache, or a build not to
    trust or that does not describe the library it points at (edited: said here). A library gone or not as
    compiled (damaged, a symlink: said by the compiler) is compiled again from the C that vouches for the same code,
    states and parameters (:func:`~.library.library_from_code`), without the model; None when there is no such C."""
    if summary is None or build is None:
        return None
    if isinstance(build, str):  # (a file not to trust: said as reading it says it)
        why = build
    elif not build.in_own_cache or summary.cycles < 1:
        return None
    elif not build.timed_parameters <= set(summary.parameters):
        why = "it names parameters its model does not have"
    else:
        verdict = check(build.library)
        if verdict.data is not None:  # (as recorded: it is loaded if it is the library its summaries describe)
            why = differences(verdict.describes, library_describes(summary, build.hash))
            if why is None:
                return library_model(summary, build.hash, build.library, options, build.timed_parameters,
                                     build.table_texts, summary.fastest)
            why = f"{build.library.name}, the library it points at, does not match it: {why}"
        else:  # (gone or not as compiled: made again from its C, the compiler says why)
            return _compiled_again(summary, build, build_file, options)
    distrust(build_file, why, WHAT)  # (edited: said once, and the summaries are written again)
    return None


def _compiled_again(summary, build: BuildSummary, build_file: Path, options: Integration):
    """The compiled model of ``build`` with its library compiled again from its C (the build summary written again
    if the library's name changed, once it has loaded), or None: no C that vouches for it (the model is loaded, its
    C generated)."""
    library = library_from_code(summary, build.hash)
    if library is None:
        return None
    compiled = library_model(summary, build.hash, library, options, build.timed_parameters, build.table_texts,
                             summary.fastest)
    if library != build.library:  # (once it has loaded: a summary never points at a library that did not)
        write_json(build_file, BuildSummary(build.hash, library, build.timed_parameters, build.table_texts).as_dict())
    return compiled


def keep_model(name: str, key: str, compiled, units=None) -> dict[Path, BuildSummary]:
    """``compiled``'s summaries written into the cache under the model ``name`` with the values of ``key``: its
    system's and its build's (under the loops it was compiled with), with the point units of a model with physical
    values (``units``: an object with ``as_dict()``, else None); the build kept, by its file (as
    :func:`read_builds` reads it)."""
    summary = SystemSummary.of(compiled.system, units is not None, compiled.fastest)
    write_json(summary_path(name, key), {"system": summary.as_dict(), "physical": units and units.as_dict()})
    build_file, build = build_path(name, key, compiled.integration), BuildSummary.of(compiled)
    write_json(build_file, build.as_dict())
    return {build_file: build}
