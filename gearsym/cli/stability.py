"""``gearsym stability MODEL --param omega=0.3:2.5:0.005 --param k_a=0:0.8:0.005``: where the static state (or the
periodic orbit) is parametrically unstable, from the Floquet multipliers at every point of a grid of two
parameters; the kind of instability and the boundaries located to a stated tolerance."""
from __future__ import annotations

import argparse
import ast
import csv
import io
import json
import sys
import time
from pathlib import Path

import numpy as np

from .. import stability  # (lazy: the linearisation, SymPy and the generator load only on a cache miss)
from ..errors import GearsymError
from ..opening import open_model
from ..options import Execution
from ..registry import model_options
from ..files.atomic import write_atomically
from ..figures.basins import axis_label
from ..figures.stability import plot_stability
from ..files.outputs import check_figure, check_file
from ..model.grammar import syntax_tree
from ..physical.basins import OwnNumbers, shown_in
from ..physical.stability import chart_in_units
from ..physical.sweeps import nondimensional_axes
from ..stability.chart import ABOUT, RELATIVE_TOLERANCE, StabilityChart, chart_axes, orbit_chart, static_chart
from ..sweep.grid import axes_from
from ..sweep.store import sidecar
from .arguments.integration import add_integration_arguments, integration_from, model_request
from .arguments.settings import add_set_argument, refuse_swept_and_set

NAME = "stability"
HELP = ("stability chart: Floquet multipliers of the static state (or the periodic orbit) over a grid of two "
        "parameters, the kind of instability and the boundaries of the tongues")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("model", help="a model name (see `gearsym list`) or the path of a model file")
    parser.add_argument("--param", action="append", required=True, metavar="NAME=START:STOP:STEP",
                        help="an axis of the chart (give two; V1,V2,... or one value also): a parameter of the model, "
                             "with a unit for a physical value (speed=2000rpm:16000rpm:100rpm)")
    add_set_argument(parser)
    parser.add_argument("--about", choices=ABOUT, default="static",
                        help="linearise about the static state (default: backlash and other non-smooth terms at the "
                             "static mesh deflection) or about the period-1 orbit (found by shooting from the static "
                             "state; a point where none is found is marked, not guessed)")
    parser.add_argument("--tolerance", type=float, default=RELATIVE_TOLERANCE, metavar="REL",
                        help=f"locate each boundary to this fraction of its axis's range (default {RELATIVE_TOLERANCE:g})")
    parser.add_argument("--no-refine", action="store_true",
                        help="do not locate the boundaries: draw them through the grid lines' midpoints")
    add_integration_arguments(parser, periods=None)
    parser.add_argument("--jobs", type=int, default=0, help="threads (default 0: one per core)")
    parser.add_argument("--no-lanes", action="store_true",
                        help="the scalar loops, one point at a time (the same numbers, slower)")
    parser.add_argument("--out", type=Path, metavar="FILE.csv",
                        help="one row per point (axes, largest modulus, stable, kind, multipliers) and FILE.json "
                             "(the grid, the boundaries, the notes)")
    parser.add_argument("--plot", type=Path, metavar="FILE.png", help="draw the chart")
    parser.add_argument("--format", choices=("text", "json"), default="text")
    parser.add_argument("--quiet", action="store_true", help="no progress output")


def run(args: argparse.Namespace) -> int:
    if args.out:
        check_file(args.out, (".csv",))
    if args.plot:
        check_figure(args.plot)
    if args.jobs < 0:
        raise GearsymError(f"--jobs must be 0 (every core) or more, got {args.jobs}")
    if not (args.tolerance > 0 and args.tolerance < 1):
        raise GearsymError(f"--tolerance {args.tolerance}: give a fraction of the axis's range, e.g. 1e-7")
    given = axes_from(args.param)
    if len(given) != 2:
        raise GearsymError(f"give two --param axes (got {len(given)}); for a line give the second one value, e.g. "
                           "--param k_a=0.2")
    options = integration_from(args)
    user = _formula_axes(args, given)
    tolerance_of = lambda axes: tuple(args.tolerance * (max(a.values) - min(a.values) or max(1.0, abs(a.values[0])))
                                      for a in axes)
    progress = None if args.quiet else _Progress()
    execution = Execution(args.jobs, lanes=not args.no_lanes, progress=progress or False)
    request = model_request(args, options)  # (after the formula's placeholders: the model is loaded with them)
    model = open_model(request)
    _refuse_model_options(args.model, given, model.slot.system)
    start = time.perf_counter()
    common = dict(refine=not args.no_refine, execution=execution)

    def checked(system):  # (the axes against the loaded model, before the compiler's seconds)
        return _checked_axes(user, given, tuple(system.parameters), model.scaling)

    if args.about == "static":  # (the linearisation's cache says whether the model is physical: no SymPy then)
        lin = model.linearised(before=checked)
        scaling = model.scaling if lin.physical else None
        axes = _checked_axes(user, given, tuple(lin.base_parameters), scaling)
        chart = static_chart(lin, axes, tolerance=tolerance_of(axes), **common)
    else:
        compiled = model.compiled(before=checked)
        scaling = model.scaling
        axes = _checked_axes(user, given, compiled.parameter_names, scaling)
        chart = orbit_chart(compiled, model.static_recipe(), axes, tolerance=tolerance_of(axes), **common)
    if progress:
        progress.done()
    prediction = None
    if args.plot and args.about == "static" and len(lin.recipe.meshes) > 1:  # (the phasing rule's panel)
        factor = given[0].values[0] / axes[0].values[0] if axes[0].values[0] else 1.0
        prediction = stability.phasing_prediction(chart, lin, factor=factor)
    shown, fixed = OwnNumbers(), None
    if scaling is not None:
        chart = chart_in_units(chart, tuple(given), tuple(axes))
        shown = shown_in(scaling.point_units())
        fixed = held_values(scaling, given)
    seconds = time.perf_counter() - start
    if args.out:
        write_table(args.out, chart)
        write_atomically(sidecar(args.out, ".json"), json.dumps(chart.as_dict(), indent=1) + "\n")
        print(f"gearsym: wrote {args.out} and {sidecar(args.out, '.json')}", file=sys.stderr)
    if args.plot:
        formula = request.settings.get("k")
        plot_stability(chart, args.plot, shown=shown, prediction=prediction, fixed=fixed,
                       title=f"{chart.model} with k(τ) = {formula}" if isinstance(formula, str) else None)
        print(f"gearsym: wrote {args.plot}", file=sys.stderr)
    if args.format == "json":
        print(json.dumps(chart.as_dict(), indent=1))
    else:
        print(report(chart, shown, seconds, fixed))
    return 0


def _refuse_model_options(model: str, given, cached: dict | None = None) -> None:
    """An axis that names a model option (planets, dof: another model built, another set of equations) cannot be
    charted: refused from the model file's options (a second: the file runs, SymPy loads), before the model is
    reduced and compiled. Where the start-up cache's summary of the model (``cached``) has every axis among its
    parameters, none is an option (an option builds the model: it is no parameter of the system built)."""
    if cached is not None and all(a.name in cached.get("parameters", ()) for a in given):
        return
    options = model_options(model)
    for a in given:
        if a.name in options:
            raise GearsymError(f"--param {a.spec!r}: {a.name} is a model option of {model} (it builds another model, "
                               f"with other equations), not a parameter a chart can move: give it one value with "
                               f"--set {a.name}={options[a.name]}, one chart per value")


def _formula_axes(args, given) -> dict:
    """A parameter that a ``--set k=...`` formula introduces (k_a in "1+k_a*cos(tau)") needs a value to load the
    model; swept, it takes its axis's first value for that (the axis sets every point's own), added to
    ``args.set``. Returns --set's values as the user gave them (without those placeholders)."""
    user = dict(args.set)
    formula = user.get("k")
    if not isinstance(formula, str):
        return user
    introduced = {n.id for n in ast.walk(syntax_tree(formula, "--set k")) if isinstance(n, ast.Name)}
    args.set = {**user, **{a.name: float(a.values[0]) for a in given
                           if a.name in introduced and a.name not in user and not a.unit}}
    return user


def _checked_axes(user: dict, given, parameters: tuple[str, ...], scaling) -> tuple:
    """The engine's axes of the --param axes ``given`` (physical ones in the model's nondimensional parameters),
    each checked to be a parameter of the model (``parameters``) and not also given with --set (``user``: its
    values as the user gave them)."""
    axes = _engine_axes(given, scaling)
    refuse_swept_and_set([(a.name, g.spec) for g, e in zip(given, axes) for a in (g, e)], user)
    return chart_axes(parameters, axes)


def _engine_axes(given, scaling):
    if scaling is None:
        unit = next((a for a in given if a.unit), None)
        if unit:
            raise GearsymError(f"--param {unit.spec!r} has a unit, but the model has no physical values; declare "
                               "them (model.set_physical) or give them with --set NAME='VALUE UNIT'")
        return tuple(given)
    return tuple(nondimensional_axes(scaling.full, given))  # (the start-up cache's stand-in converts no axis)


def write_table(path: Path, chart: StabilityChart) -> None:
    """One row per point: the two axes (as given, with their units), the largest modulus, stable, kind, the
    multipliers (real and imaginary parts, largest modulus first)."""
    (na, nb), (ua, ub) = chart.names, chart.units
    a, b = chart.values
    n = chart.multipliers.shape[-1]
    text = io.StringIO()
    writer = csv.writer(text, lineterminator="\n")
    writer.writerow([f"{na} [{ua}]" if ua else na, f"{nb} [{ub}]" if ub else nb, "max_modulus", "stable", "kind",
                     *(f"mu_{i + 1}_{part}" for i in range(n) for part in ("re", "im"))])
    for i in range(len(b)):
        for j in range(len(a)):
            mu = chart.multipliers[i, j]
            stable = chart.stable[i, j]
            writer.writerow([repr(float(a[j])), repr(float(b[i])), _number(chart.max_modulus[i, j]),
                             "" if stable is None else str(bool(stable)).lower(), chart.kind[i, j] or "",
                             *(_number(x) for m in mu for x in (m.real, m.imag))])
    write_atomically(path, text.getvalue())


def _number(x: float) -> str:
    return repr(float(x)) if np.isfinite(x) else ""


def held_values(scaling, given) -> str:
    """The physical values held over a chart, as the user gave them: all but its axes' own (and the speed, for an
    axis of omega); an axis in the engine's numbers (zeta) is said with the physical values it is made of, which
    it overrides."""
    units = scaling.point_units()
    axes = {a.name for a in given}
    names = axes | ({scaling.speed.parameter} if scaling.speed and "omega" in axes else set())
    groups = {g.name: g for g in scaling.full.model.groups}
    overridden = [f"{a.name} charted in the engine's numbers over the values it is made of ("
                  + ", ".join(sorted(str(x) for x in groups[a.name].definition.free_symbols)) + ")"
                  for a in given if a.name in groups]
    return "; ".join([units.parameters_text(leave_out=names), *overridden])


def report(chart: StabilityChart, shown: OwnNumbers, seconds: float, fixed: str | None = None) -> str:
    """The chart's text; ``fixed``: the values held over it as the user gave them (a model with physical values),
    else the chart's own numbers."""
    (na, nb), (ua, ub) = chart.names, chart.units
    a, b = chart.values
    lines = [f"{chart.model}: stability of its {'static state' if chart.about == 'static' else 'period-1 orbit'} "
             f"on {len(a)} x {len(b)} points, {axis_label(na, ua)} in [{a.min():g}, {a.max():g}] x "
             f"{axis_label(nb, ub)} in [{b.min():g}, {b.max():g}] ({seconds:.2f} s)",
             f"fixed: {(fixed if fixed is not None else shown.parameters(chart.fixed)).replace('$', '')}",
             "points: " + ", ".join(f"{k} {v}" for k, v in chart.counts().items())]
    t = chart.timings
    if chart.crossings:
        lines.append(f"boundaries: {len(chart.boundaries)} curve(s) through {len(chart.crossings)} points on the grid "
                     f"lines, located to {', '.join(f'{n} {tol:.3g}' for n, tol in zip(chart.names, chart.tolerance))}"
                     f" ({t.get('periods_per_boundary_point', 0):.1f} periods per point)")
        by_kind = {}
        for c in chart.boundaries:
            by_kind[c.kind] = by_kind.get(c.kind, 0) + 1
        lines.append("  " + ", ".join(f"{k}: {v} curve(s)" for k, v in by_kind.items()))
    else:
        lines.append("boundaries: none on this grid")
    lines += [f"note: {n}" for n in chart.notes]
    return "\n".join(lines).replace("$", "")  # (no figure mathtext in text)


class _Progress:
    """One line on stderr, rewritten at most a few times a second."""

    def __init__(self):
        self.shown = False

    def __call__(self, line: str) -> None:  # (the chart says a stage's count at most every PROGRESS_EVERY s)
        end = "\r" if sys.stderr.isatty() else "\n"
        print(f"gearsym: {line}", end=end, file=sys.stderr, flush=True)
        self.shown = True

    def done(self) -> None:
        if self.shown and sys.stderr.isatty():
            print(file=sys.stderr)
