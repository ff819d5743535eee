"""A start-up cache entry for new plain parameter values, made from the entry of the same model without them.

``gearsym lyap planetary --set omega=0.82`` after any run of ``planetary`` at its own values: the reduction and
the code do not depend on a parameter's value (a value is a default of the system's parameter vector, never in
the code), so the summaries the cache keeps for the model without the new values (its base entry) hold the same
names, states, constraints, contact watches and libraries. What does depend on the values is recomputed here,
without SymPy: the values themselves, and the fastest linearised mode's rate and the forcing period (the step's
choice), from the Jacobian and period of the base entry's own library
(:func:`~.mode_rates.compiled_rate`: the functions every build of a model shares). Loading SymPy, running the
model file and reducing (about a second) are saved.

An entry is derived only where that reasoning holds, else the model is loaded as before (which also says what is
wrong with a bad value): the new values are plain finite numbers of parameters the base entry's system has, each
within its constraint; the base entry is of a model without physical values (a physical model's values enter its
scaling) whose file declares no model options (an option is given to the file's ``build`` and may change the
model); and a library of the base entry is found and trusted (:func:`~.kept.kept_model`).
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path

from ..errors import GearsymError
from ..options import Integration
from .code_files import code_directory, read_manifest
from .kept import BuildSummary, build_path, kept_model, read_builds, read_json, summary_path, write_json
from .mode_rates import compiled_rate
from .system_summary import read_summary


def derived_entry(path: Path, base_key: str, key: str, plain: Mapping[str, float]) -> dict | None:
    """The system's summary (as the cache keeps it: ``{"system": ..., "physical": None}``) of the model in the file
    ``path`` with the values of ``key``, which are those of ``base_key`` and the plain numbers ``plain``, derived
    from the base entry and written under ``key`` with the base entry's builds; None where none is derived (see
    above)."""
    if _may_declare_options(path):
        return None
    name = path.stem
    base = read_json(summary_path(name, base_key))
    summary = read_summary(base.get("system") if base is not None else None, _never)
    if summary is None or summary.physical or not plain or base.get("physical") is not None:
        return None
    for parameter, value in plain.items():
        constraint = summary.constraints.get(parameter)
        if parameter not in summary.parameters or (constraint is not None and constraint.violation(value)):
            return None
    builds = {file: build for file, build in read_builds(name, base_key).items()
              if isinstance(build, BuildSummary)}  # (one not to trust, edited, is not taken over)
    rates = next((found for found in (_rate(summary, name, base_key, file, build, plain)
                                      for file, build in builds.items()) if found is not None), None)
    if rates is None:
        return None
    fastest, cycle = rates
    derived = replace(summary, parameters={**summary.parameters, **plain}, fastest=fastest, cycle=cycle)
    entry = {"system": derived.as_dict(), "physical": None}
    for file, build in builds.items():  # (the same code for the loops each names, kept under the new key)
        loops = file.stem[len(f"{name}-{base_key}-"):]
        write_json(summary_path(name, f"{key}-{loops}"), build.as_dict())
    write_json(summary_path(name, key), entry)
    return entry


def _may_declare_options(path: Path) -> bool:
    """Whether the model file may declare model options (``OPTIONS``, given to its ``build``: ``--set planets=4``
    changes the model, and an option may share a parameter's name): told from its text, without running it."""
    try:
        return b"OPTIONS" in path.read_bytes()
    except OSError:
        return True


def _rate(summary, name: str, base_key: str, build_file: Path, build, plain: Mapping[str, float]):
    """The fastest rate and the forcing period at the base values with ``plain``, from the library of
    ``build_file`` (None: no library to trust, or no positive period there)."""
    options = _build_options(summary, name, base_key, build_file, build)
    compiled = None if options is None else kept_model(summary, build, build_file, options)
    return None if compiled is None else compiled_rate(compiled, plain)


def _build_options(summary, name: str, base_key: str, build_file: Path, build) -> Integration | None:
    """The options ``build`` was compiled with (its code's manifest says its loops), if they are those its file is
    kept under, else None: the compiled model is loaded with them, and this process reuses it for a run."""
    try:
        loops = read_manifest(code_directory(summary.name, build.hash))["options"]
        options = Integration(steps_per_period=int(loops["steps_per_period"]) // summary.cycles,
                              integrator=str(loops["method"]), locate_crossings=bool(loops["locate_crossings"]))
    except (KeyError, TypeError, ValueError, GearsymError):
        return None
    return options if build_path(name, base_key, options) == build_file else None


def _never():
    raise AssertionError("a derived entry reads the base summary's numbers only")  # (never its symbolic part)
