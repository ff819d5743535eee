"""``gearsym basins MODEL --grid x=-5:5:0.1 --grid v=-5:5:0.1``: basins of attraction on a grid of starts, and
their fractions along a parameter (``--param omega=1.3:1.8:0.01``, resumable)."""
from __future__ import annotations

import argparse
import csv
import io
import json
import sys
from pathlib import Path

from ..analysis.basins import CLASSES, RUN, BasinMap, basin_map
from ..errors import GearsymError
from ..figures.basins import Shown, plot_basin_fractions, plot_basin_map
from ..files.atomic import write_atomically
from ..files.outputs import check_figure, check_file
from ..physical.basins import PhysicalShown, check_grid_units, engine_grid, physical_dict, units_of
from ..physical.sweeps import nondimensional_axes
from ..sweep.basin_continuation import MATCH_DISTANCE, continue_basins
from ..sweep.grid import Axis, axes_from, parse_axis
from ..sweep.store import sidecar
from .integration import add_integration_arguments, compiled_from, scaling_from
from .settings import add_set_argument, parse_state

NAME = "basins"
HELP = "basins of attraction on a grid of starts (attractors by their Poincare sets), and their fractions along a parameter"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("model", help="a model name (see `gearsym list`) or the path of a model file")
    add_set_argument(parser)
    parser.add_argument("--grid", action="append", required=True, metavar="STATE=START:STOP:STEP",
                        help="the starts of one state (stop included; V1,V2,... also); give two states, the "
                             "others are held at --y0 (a model with physical values: with units, x=-20um:20um:1um, "
                             "v=-500mm/s:500mm/s:25mm/s)")
    parser.add_argument("--y0", metavar="x1=0,v1=0", help="where the states off the grid start (default: the model's)")
    parser.add_argument("--param", metavar="NAME=START:STOP:STEP",
                        help="the basin fractions along this parameter, each attractor followed by its Poincare "
                             "set (needs --out; resumable: the same command continues an interrupted run)")
    add_integration_arguments(parser, **RUN)
    parser.add_argument("--jobs", type=int, default=0, help="threads (default 0: one per core)")
    parser.add_argument("--no-lanes", action="store_true",
                        help="the scalar loops, one start at a time (the same numbers, slower)")
    parser.add_argument("--out", type=Path, metavar="FILE.csv",
                        help="a map: one row per start (its attractor) and FILE.json; with --param: one row per "
                             "attractor and value, FILE.attractors.csv (Poincare points) and FILE.json")
    parser.add_argument("--overwrite", action="store_true", help="with --param: start again instead of resuming")
    parser.add_argument("--match-distance", type=float, default=MATCH_DISTANCE, metavar="D",
                        help=f"with --param: how far (in units of the points' spread) an attractor may move between "
                             f"neighbouring values and still be the same (default {MATCH_DISTANCE})")
    parser.add_argument("--plot", type=Path, metavar="FILE.png",
                        help="the basin map (with --param: the fractions and amplitudes along the parameter)")
    parser.add_argument("--format", choices=("text", "json"), default="text")
    parser.add_argument("--quiet", action="store_true", help="no progress output")


def run(args: argparse.Namespace) -> int:
    if args.out:
        check_file(args.out, (".csv",))
    if args.param and not args.out:
        raise GearsymError("--param follows the basins along a parameter into files: give --out FILE.csv")
    if args.plot:
        check_figure(args.plot)
    if args.jobs < 0:
        raise GearsymError(f"--jobs must be 0 (every core) or more, got {args.jobs}")
    grid_axes = [parse_axis(g, "--grid") for g in args.grid]
    if len(grid_axes) != 2 or grid_axes[0].name == grid_axes[1].name:
        raise GearsymError(f"--grid: give two different states (e.g. --grid x=-5:5:0.1 --grid v=-5:5:0.1), got "
                           f"{', '.join(a.name for a in grid_axes) or 'none'}")
    y0 = parse_state(args.y0)
    axis = axes_from([args.param])[0] if args.param else None
    scaling = scaling_from(args)
    units = units_of(scaling) if scaling is not None else None
    if units is None:
        unit = next((a for a in [*grid_axes, *([axis] if axis else [])] if a.unit), None)
        if unit:
            raise GearsymError(f"{unit.spec!r} has a unit, but the model has no physical values; give the model's own "
                               "numbers")
    if units is not None:
        check_grid_units(units, grid_axes)  # (before the model is compiled)
    if axis is not None and units is not None:
        axis = nondimensional_axes(scaling, [axis])[0]
    compiled = compiled_from(args)
    shown = PhysicalShown(units) if units is not None else Shown()
    if axis is not None:
        return _continuation(args, compiled, grid_axes, axis, units, shown, y0)
    omega = compiled.parameter_vector()[compiled.parameter_names.index("omega")] \
        if "omega" in compiled.parameter_names else 1.0
    grid = engine_grid(units, grid_axes, omega) if units is not None else {a.name: a.values for a in grid_axes}
    result = basin_map(compiled, grid, y0=y0, jobs=args.jobs, lanes=not args.no_lanes, verbose=not args.quiet)
    if args.out:
        _write_map(args.out, result, shown, grid_axes)
        print(f"gearsym: wrote {args.out} and {sidecar(args.out, '.json')}", file=sys.stderr)
    if args.plot:
        plot_basin_map(result, args.plot, shown)
        print(f"gearsym: wrote {args.plot}", file=sys.stderr)
    if args.format == "json":
        data = physical_dict(result, shown, grid_axes) if units is not None else result.as_dict()
        print(json.dumps(data, indent=2))
    else:
        print(report(result, shown))
    return 0


def _continuation(args, compiled, grid_axes: list[Axis], axis: Axis, units, shown, y0) -> int:
    if units is not None:
        def grid(point):
            return engine_grid(units, grid_axes, point.get("omega", 1.0))
    else:
        grid = {a.name: a.values for a in grid_axes}
    try:
        result = continue_basins(compiled, grid, axis.name, axis.values, y0=y0, out=args.out,
                                 overwrite=args.overwrite, jobs=args.jobs, lanes=not args.no_lanes,
                                 match_distance=args.match_distance, grid_spec=args.grid,
                                 progress=not args.quiet)
    except KeyboardInterrupt:
        print(f"gearsym: interrupted; the values finished are in {args.out}: run the same command again to resume",
              file=sys.stderr)
        return 130
    if units is not None:
        path = sidecar(args.out, ".physical.csv")
        _write_physical_fractions(path, result, shown)
        print(f"gearsym: wrote {path} (the fractions in the model's units)", file=sys.stderr)
    if args.plot:
        plot_basin_fractions(result, args.plot, shown)
        print(f"gearsym: wrote {args.plot}", file=sys.stderr)
    if args.format == "json":
        print(json.dumps(result.as_dict(), indent=2))
    else:
        print(continuation_report(result, shown))
    return 0


def _write_physical_fractions(path: Path, result, shown) -> None:
    """The continuation's rows with the parameter as the speed and amplitudes in the length unit."""
    name, values, unit = shown.parameter(result.parameter, result.values)
    speed = dict(zip(result.values, values))
    coordinates = list(dict.fromkeys(k for r in result.rows for k in r.amplitude))
    units = {k: shown.state(k, [0.0], 1.0)[1] for k in coordinates}
    text = io.StringIO()
    writer = csv.writer(text, lineterminator="\n")
    writer.writerow([f"{name} [{unit}]" if unit else name, "class", "attractor", "fraction", "stderr", "period",
                     "regime", *(f"A_{k} [{units[k]}]" if units[k] else f"A_{k}" for k in coordinates)])
    for r in result.rows:
        amplitude = [repr(float(shown.state(k, [r.amplitude[k]], r.value)[0][0])) if k in r.amplitude else ""
                     for k in coordinates]
        writer.writerow([repr(float(speed[r.value])), r.kind, "" if r.id is None else r.id, repr(r.fraction),
                         repr(r.stderr), "" if r.period is None else r.period, r.regime, *amplitude])
    write_atomically(path, text.getvalue())


def _write_map(path: Path, result: BasinMap, shown, axes: list[Axis]) -> None:
    """One row per start: the grid's two states (as given) and the class it reached; the record beside it."""
    (x, xs), (y, ys) = result.axes
    omega = result.parameters.get("omega")
    sx, ux = shown.state(x, xs, omega)
    sy, uy = shown.state(y, ys, omega)
    text = io.StringIO()
    writer = csv.writer(text, lineterminator="\n")
    writer.writerow([f"{x} [{ux}]" if ux else x, f"{y} [{uy}]" if uy else y, "attractor"])
    names = CLASSES
    for j, yv in enumerate(sy):
        for i, xv in enumerate(sx):
            label = int(result.labels[j, i])
            writer.writerow([repr(float(xv)), repr(float(yv)), names.get(label, label)])
    write_atomically(path, text.getvalue())
    data = physical_dict(result, shown, axes) if hasattr(shown, "units") else result.as_dict()
    data.pop("labels", None)
    write_atomically(sidecar(path, ".json"), json.dumps(data, indent=2) + "\n")


def report(result: BasinMap, shown) -> str:
    """The text output: the run, each attractor, the other classes."""
    omega = result.parameters.get("omega")
    (x, xs), (y, ys) = result.axes
    sx, ux = shown.state(x, xs, omega)
    sy, uy = shown.state(y, ys, omega)
    held = ", ".join(f"{k}={float(shown.state(k, [v], omega)[0][0]):g}{shown.state(k, [v], omega)[1]}"
                     for k, v in result.held.items())
    lines = [
        f"{result.model}: {result.starts} starts, {x} in [{sx.min():g}, {sx.max():g}]{ux} ({xs.size}) x {y} in "
        f"[{sy.min():g}, {sy.max():g}]{uy} ({ys.size})" + (f", held {held}" if held else ""),
        f"parameters: {shown.parameters(result.parameters).replace('$', '')}",  # (no figure mathtext in text)
        f"{result.periods} periods per start ({result.discard} discarded), {result.steps_per_period} RK4 steps/period, "
        f"{'crossings located' if result.locate_crossings else 'plain RK4'}, {result.backend}, "
        f"{result.lanes} trajectories per call",
        f"{len(result.attractors)} attractor{'s' if len(result.attractors) != 1 else ''} (fraction of starts ± "
        "binomial standard error; exponents from one tangent run on each):",
    ]
    for a in result.attractors:
        amplitude = ", ".join(f"A_{k} = {float(shown.state(k, [v], omega)[0][0]):.6g}{_unit(shown, k, omega)}"
                              for k, v in a.amplitude.items())
        lines += [f"  {a.number}: {a.description}: {a.fraction:.4f} ± {a.stderr:.4f} ({a.basin.starts} starts)",
                  f"     {amplitude}; lambda = " + ", ".join(f"{v:+.5f}" for v in a.exponents)]
    for name, share in (("diverged", result.diverged), ("undetermined", result.undetermined)):
        lines.append(f"  {name}: {share.fraction:.4f} ± {share.stderr:.4f} ({share.starts} starts)")
    return "\n".join(lines)


def _unit(shown, name: str, omega) -> str:
    unit = shown.state(name, [0.0], omega)[1]
    return f" {unit}" if unit else ""


def continuation_report(result, shown) -> str:
    name, values, unit = shown.parameter(result.parameter, result.values)
    lines = [f"{result.model}: basin fractions at {len(values)} values of {name} ({values[0]:g} to {values[-1]:g}"
             f"{' ' + unit if unit else ''}) -> {result.path}"]
    where = dict(zip(result.values, values))
    for v in result.values:
        parts = [f"{r.id}: {r.fraction:.3f} ({r.period and f'period {r.period}' or r.regime})"
                 for r in result.at(v) if r.kind == "attractor"]
        other = [f"{r.kind} {r.fraction:.3f}" for r in result.at(v) if r.kind != "attractor" and r.starts]
        lines.append(f"  {name}={where[v]:g}: " + "; ".join(parts + other))
    for e in result.events:
        what = f"attractor {e['attractor']} {e['event']}" + (f" into {e['into']}" if e["into"] else "")
        lines.append(f"  at {name}={where[e['value']]:g}: {what}")
    return "\n".join(lines)
