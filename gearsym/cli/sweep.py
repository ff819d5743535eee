"""``gearsym sweep MODEL --param omega=0.1:2.0:0.01``: Lyapunov spectra and amplitudes over a grid."""
from __future__ import annotations

import argparse
import sys
from collections import Counter
from pathlib import Path

import numpy as np

from ..checks import chosen_coordinate
from ..errors import GearsymError
from ..figures.sweep import plot_sweep
from ..files.outputs import check_figure, check_file
from ..physical.files import write_physical_record, write_physical_table
from ..physical.sweeps import nondimensional_axes
from ..opening import open_model
from ..options import PARALLEL, Execution
from ..sweep import DIRECTIONS, MODES, POINCARE_SAMPLES, Workers, run_sweep
from ..sweep.grid import axes_from
from ..sweep.run import poincare_samples_of
from ..sweep.report import findings_lines
from ..sweep.store import sidecar
from .arguments.integration import add_integration_arguments, integration_from, model_request, step_line
from .arguments.settings import add_set_argument, parse_state, refuse_swept_and_set

NAME = "sweep"
HELP = "Lyapunov spectra, amplitudes and regimes over a 1-D or 2-D parameter grid (resumable)"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("model", help="a model name (see `gearsym list`) or the path of a model file")
    parser.add_argument("--param", action="append", required=True, metavar="NAME=VALUES",
                        help="a swept parameter: START:STOP:STEP (stop included), V1,V2,... or one value, with a "
                             "unit for a physical value (speed=500rpm:6000rpm:25rpm); repeat for a 2-D grid (a "
                             "continuation follows the first)")
    add_set_argument(parser)
    parser.add_argument("--mode", choices=MODES, default="continuation",
                        help="continuation: each point starts from the last state of the previous one (the "
                             "paper's procedure); independent: every point from the initial state, in parallel")
    parser.add_argument("--direction", choices=DIRECTIONS, default="up",
                        help="continuation along the first parameter: ascending, descending, or up then down "
                             "(shows hysteresis)")
    add_integration_arguments(parser)
    parser.add_argument("--y0", metavar="x=-2,v=-0.5", help="initial state (default: the model's)")
    parser.add_argument("--jobs", type=int, default=0,
                        help="processes or threads (default 0: every core); with --dask, worker processes")
    parser.add_argument("--parallel", choices=PARALLEL, default="auto",
                        help="how --jobs run on this machine: forked processes (auto, where the OS can fork) "
                             "or threads")
    cluster = parser.add_mutually_exclusive_group()
    cluster.add_argument("--dask", action="store_true",
                         help='run the points on a Dask cluster of --jobs processes started on this machine for '
                              'this sweep (needs pip install "gearsym[distributed]")')
    cluster.add_argument("--scheduler", metavar="tcp://HOST:PORT",
                         help="run the points on the Dask cluster of this scheduler (`dask scheduler`, "
                              "`dask worker tcp://HOST:PORT`; every worker needs gearsym)")
    parser.add_argument("--out", type=Path, required=True, metavar="FILE.csv",
                        help="the table; FILE.json (record, jumps) and FILE.poincare.csv are written beside it. "
                             "If they exist, the same command resumes them")
    parser.add_argument("--overwrite", action="store_true", help="start again instead of resuming")
    parser.add_argument("--poincare", type=int, default=POINCARE_SAMPLES, metavar="K",
                        help=f"stroboscopic samples kept per point, for bifurcation diagrams (default {POINCARE_SAMPLES})")
    parser.add_argument("--plot", type=Path, metavar="FILE.png",
                        help="draw amplitudes, exponents, regimes and the bifurcation diagram")
    parser.add_argument("--coordinate", metavar="NAME",
                        help="the coordinate --plot shows (amplitude, bifurcation diagram; default the first)")
    parser.add_argument("--lanes", action="store_true",
                        help="independent points run several at once in SIMD lanes, each with its own parameters: "
                             "the same numbers (to rounding with fused multiply-adds), faster")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")


def run(args: argparse.Namespace) -> int:
    check_file(args.out, (".csv",))
    if args.plot:
        check_figure(args.plot)
    execution = Execution(args.jobs, args.parallel, "local" if args.dask else args.scheduler, lanes=args.lanes,
                          progress=not args.quiet)
    Workers.of(execution)  # (no Dask, a bad address, more jobs than cores: said before the model is compiled)
    y0 = parse_state(args.y0)  # before the model is compiled
    options = integration_from(args)  # (sizes too) before the model is loaded
    poincare_samples_of(args.poincare, options)
    request = model_request(args, options)
    given = axes_from(args.param)
    model = open_model(request)
    scaling = model.scaling
    axes = _engine_axes(given, scaling)
    refuse_swept_and_set([(a.name, g.spec) for g, e in zip(given, axes) for a in (g, e)], args.set)
    compiled = model.compiled(over={a.name: a.values for a in axes})  # (the step its fastest point needs)
    chosen_coordinate(args.coordinate, compiled.observed, args.plot)
    if not args.quiet:
        print(f"gearsym: {step_line(compiled, scaling)}", file=sys.stderr)
    try:
        result = run_sweep(compiled, axes, mode=args.mode, direction=args.direction, y0=y0,
                           out=args.out, overwrite=args.overwrite, poincare=args.poincare, execution=execution)
    except KeyboardInterrupt as exc:  # SweepInterrupted says how many points were kept
        print(f"gearsym: {exc}" if str(exc) else "gearsym: interrupted before any point was finished",
              file=sys.stderr)
        return 130
    regimes = Counter(result["regime"].tolist())
    physical = scaling is not None
    print(f"{result.model}: {len(result)} points -> {args.out} (+ .json, .poincare.csv"
          + (", .physical.csv, .physical.json)" if physical else ")"))
    print("regimes: " + ", ".join(f"{k} {v}" for k, v in sorted(regimes.items())))
    for line in verdict_lines(result):
        print(line)
    if physical:  # the findings along the values swept, in their units, and the tables in them
        result = scaling.to_physical(result, given=given)
        record = write_physical_record(result, sidecar(args.out, ".physical.json"))
        for line in findings_lines(result, record, result.record["physical"]):
            print(line)
        print(f"in physical units: {write_physical_table(result, sidecar(args.out, '.physical.csv'))} "
              f"(and {record})")
    else:
        for line in findings_lines(result, sidecar(args.out, ".json")):
            print(line)
    if args.plot:
        plot_sweep(result, args.plot, coordinate=args.coordinate)
        print(f"gearsym: wrote {args.plot}", file=sys.stderr)
    return 0


def verdict_lines(result) -> list[str]:
    """What the sweep's 'diverged' and 'undetermined' points mean, where there are any (see docs/engine.md)."""
    lines, first = [], result.axes[0].name
    diverged = result["regime"] == "diverged"
    if diverged.any():
        values = result[first][diverged]
        lines.append(f"  diverged at {diverged.sum()} point(s), {first} in [{values.min():g}, {values.max():g}]: the "
                     "motion grew without bound there (no regime; `gearsym lyap` at one says how and why); a "
                     "continuation went on from the last point that did not")
    undetermined = int(np.sum(result["regime"] == "undetermined"))
    if undetermined:
        lines.append(f"  undetermined at {undetermined} point(s): lambda_1 could not be told from 0 there and the "
                     "Poincare points did not settle (a transient, or too few periods to say); `gearsym lyap` at one "
                     "says how many periods would decide, or run again with more --periods and --discard")
    return lines


def _engine_axes(axes, scaling):
    """The --param axes the engine sweeps: physical ones (speed=500rpm:6000rpm:25rpm) turned into the
    nondimensional parameter they move, for a model with physical values."""
    if scaling is None:
        unit = next((a for a in axes if a.unit), None)
        if unit:
            raise GearsymError(f"--param {unit.spec!r} has a unit, but the model has no physical values; declare "
                               "them (model.set_physical) or give them with --set NAME='VALUE UNIT'")
        return axes

    return nondimensional_axes(scaling.full, axes)
