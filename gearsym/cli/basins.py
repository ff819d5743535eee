"""``gearsym basins MODEL --grid x=-5:5:0.1 --grid v=-5:5:0.1``: basins of attraction on a grid of starts, and
their fractions along a parameter (``--param omega=1.3:1.8:0.01``, resumable)."""
from __future__ import annotations

import argparse
import json
import sys

from ..analysis.basins import RUN, basin_map
from ..errors import GearsymError
from ..figures.basins import save_basin_fractions, save_basin_map
from ..files.outputs import check_figure, check_file
from ..opening import open_model
from ..options import Execution
from ..physical.basins import GivenGrid, GridAxis, ShownBasinMap, ShownFractions, shown_in
from ..physical.sweeps import MeasuredAxis, engine_axis
from ..sweep.basin_continuation import MATCH_DISTANCE, continue_basins
from ..sweep.store import sidecar
from .arguments.integration import add_integration_arguments, integration_from, model_request
from .arguments.settings import add_set_argument, parse_state

NAME = "basins"
HELP = "basins of attraction on a grid of starts (attractors by their Poincare sets), and their fractions along a parameter"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("model", help="a model name (see `gearsym list`) or the path of a model file")
    add_set_argument(parser)
    parser.add_argument("--grid", type=GridAxis.read, action="append", required=True, metavar="STATE=START:STOP:STEP",
                        help="the starts of one state (stop included; V1,V2,... also); give two states, the "
                             "others are held at --y0 (a model with physical values: with units, x=-20um:20um:1um, "
                             "v=-500mm/s:500mm/s:25mm/s)")
    parser.add_argument("--y0", type=parse_state, metavar="x1=0,v1=0",
                        help="where the states off the grid start (default: the model's)")
    parser.add_argument("--param", type=MeasuredAxis.read, metavar="NAME=START:STOP:STEP",
                        help="the basin fractions along this parameter, each attractor followed by its Poincare "
                             "set (needs --out; resumable: the same command continues an interrupted run)")
    add_integration_arguments(parser, **RUN)
    parser.add_argument("--jobs", type=int, default=0, help="threads (default 0: one per core)")
    parser.add_argument("--no-lanes", action="store_true",
                        help="the scalar loops, one start at a time (the same numbers, slower)")
    parser.add_argument("--out", type=lambda text: check_file(text, (".csv",)), metavar="FILE.csv",
                        help="a map: one row per start (its attractor) and FILE.json; with --param: one row per "
                             "attractor and value, FILE.attractors.csv (Poincare points) and FILE.json")
    parser.add_argument("--overwrite", action="store_true", help="with --param: start again instead of resuming")
    parser.add_argument("--match-distance", type=float, default=MATCH_DISTANCE, metavar="D",
                        help=f"with --param: how far (in units of the points' spread) an attractor may move between "
                             f"neighbouring values and still be the same (default {MATCH_DISTANCE})")
    parser.add_argument("--plot", type=check_figure, metavar="FILE.png",
                        help="the basin map (with --param: the fractions and amplitudes along the parameter)")
    parser.add_argument("--format", choices=("text", "json"), default="text")
    parser.add_argument("--quiet", action="store_true", help="no progress output")


def run(args: argparse.Namespace) -> int:
    """(The arguments are read and checked as they are parsed: --grid and --param into axes, --y0 into numbers,
    --out and --plot where they go.)"""
    if args.param and not args.out:
        raise GearsymError("--param follows the basins along a parameter into files: give --out FILE.csv")
    if args.jobs < 0:
        raise GearsymError(f"--jobs must be 0 (every core) or more, got {args.jobs}")
    grid_axes, axis = args.grid, args.param
    if len(grid_axes) != 2 or grid_axes[0].name == grid_axes[1].name:
        raise GearsymError(f"--grid: give two different states (e.g. --grid x=-5:5:0.1 --grid v=-5:5:0.1), got "
                           f"{', '.join(a.name for a in grid_axes) or 'none'}")
    execution = Execution(args.jobs, lanes=not args.no_lanes, progress=not args.quiet)
    request = model_request(args, integration_from(args))
    model = open_model(request)
    scaling = model.scaling
    units = scaling.point_units() if scaling is not None else None
    if units is None:
        unit = next((a for a in [*grid_axes, *([axis] if axis else [])] if a.unit), None)
        if unit:
            raise GearsymError(f"{unit.spec!r} has a unit, but the model has no physical values; give the model's own "
                               "numbers")
    shown_as = shown_in(units, request.settings)
    # (the starts, made once for the map or every value of the continuation: a grid in physical units is checked
    # here, once, before the model is compiled, and its engine values are taken where the starts are made)
    grid = GivenGrid(units, grid_axes)
    if axis is not None and units is not None:  # (the parameter in the engine's numbers, also before)
        axis = engine_axis(scaling.full, axis)
    compiled = model.compiled()
    if axis is None:
        shown = ShownBasinMap(basin_map(compiled, grid, y0=args.y0, execution=execution), shown_as, grid.axes)
        written = save_basin_map(shown, args.out, args.plot)
        if args.out:
            print(f"gearsym: wrote {written[0]} and {written[1]}", file=sys.stderr)
        _said_plot(args.plot)
        print(json.dumps(shown.as_dict(), indent=2) if args.format == "json" else report(shown))
        return 0
    try:
        result = continue_basins(compiled, grid, axis.name, axis.values, y0=args.y0, out=args.out,
                                 overwrite=args.overwrite, execution=execution, match_distance=args.match_distance)
    except KeyboardInterrupt:
        print(f"gearsym: interrupted; the values finished are in {args.out}: run the same command again to resume",
              file=sys.stderr)
        return 130
    shown = ShownFractions(result, shown_as)
    physical = sidecar(args.out, ".physical.csv") if units is not None else None
    save_basin_fractions(shown, physical, args.plot)
    if physical is not None:
        print(f"gearsym: wrote {physical} (the fractions in the model's units)", file=sys.stderr)
    _said_plot(args.plot)
    print(json.dumps(result.as_dict(), indent=2) if args.format == "json" else continuation_report(shown))
    return 0


def _said_plot(plot: str | None) -> None:
    if plot:
        print(f"gearsym: wrote {plot}", file=sys.stderr)


def report(shown: ShownBasinMap) -> str:
    """The text output: the run, each attractor, the other classes."""
    result = shown.result
    (x, xs), (y, ys) = result.axes
    sx, ux = shown.state(x, xs)
    sy, uy = shown.state(y, ys)
    held = ", ".join("{}={:g}{}".format(k, *shown.number(k, v)) for k, v in result.held.items())
    lines = [
        f"{result.model}: {result.starts} starts, {x} in [{sx.min():g}, {sx.max():g}]{ux} ({xs.size}) x {y} in "
        f"[{sy.min():g}, {sy.max():g}]{uy} ({ys.size})" + (f", held {held}" if held else ""),
        f"parameters: {shown.parameters_text().replace('$', '')}",  # (no figure mathtext in text)
        f"{result.periods} periods per start ({result.discard} discarded), {result.steps_per_period} RK4 steps/period, "
        f"{'crossings located' if result.locate_crossings else 'plain RK4'}, {result.backend}, "
        f"{result.lanes} trajectories per call",
        f"{len(result.attractors)} attractor{'s' if len(result.attractors) != 1 else ''} (fraction of starts ± "
        "binomial standard error; exponents from one tangent run on each):",
    ]
    for a in result.attractors:
        amplitude = ", ".join("A_{} = {:.6g}{}".format(k, *_spaced(shown.number(k, v)))
                              for k, v in a.amplitude.items())
        lines += [f"  {a.number}: {a.description}: {a.fraction:.4f} ± {a.stderr:.4f} ({a.basin.starts} starts)",
                  f"     {amplitude}; lambda = " + ", ".join(f"{v:+.5f}" for v in a.exponents)]
    for name, share in (("diverged", result.diverged), ("undetermined", result.undetermined)):
        lines.append(f"  {name}: {share.fraction:.4f} ± {share.stderr:.4f} ({share.starts} starts)")
    return "\n".join(lines)


def _spaced(number: tuple[float, str]) -> tuple[float, str]:
    value, unit = number
    return value, f" {unit}" if unit else ""


def continuation_report(shown: ShownFractions) -> str:
    result = shown.result
    name, values, unit = shown.parameter()
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
