"""``gearsym basins MODEL --grid x=-5:5:0.1 --grid v=-5:5:0.1``: basins of attraction on a grid of starts, and
their fractions along a parameter (``--param omega=1.3:1.8:0.01``, resumable)."""
from __future__ import annotations

import argparse
import sys

from ..analysis.basins import RUN
from ..jobs.basins import BasinFractionsJob, BasinMapJob, BasinsJob, FractionsInterrupted
from ..errors import GearsymError
from ..files.outputs import check_figure, check_file
from ..opening import open_model
from ..options import Execution
from ..physical.basins import GridAxis
from ..physical.sweeps import MeasuredAxis
from ..sweep.basin_continuation import MATCH_DISTANCE
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
    if len(args.grid) != 2 or args.grid[0].name == args.grid[1].name:
        raise GearsymError(f"--grid: give two different states (e.g. --grid x=-5:5:0.1 --grid v=-5:5:0.1), got "
                           f"{', '.join(a.name for a in args.grid) or 'none'}")
    job = job_from(args)
    request = model_request(args, integration_from(args))
    model = open_model(request)
    try:
        done = job.run(model)
    except FractionsInterrupted:
        print(f"gearsym: interrupted; the values finished are in {args.out}: run the same command again to resume",
              file=sys.stderr)
        return 130
    for line in done.written:
        print(f"gearsym: {line}", file=sys.stderr)
    print(done.report(args.format))
    return 0


def job_from(args: argparse.Namespace) -> BasinsJob:
    """The job the arguments ask for: the fractions along --param, else a map."""
    given = {"grid": tuple(args.grid), "y0": args.y0, "plot": args.plot, "out": args.out,
             "execution": Execution(args.jobs, lanes=not args.no_lanes, progress=not args.quiet)}
    if args.param is None:
        return BasinMapJob(**given)
    return BasinFractionsJob(**given, parameter=args.param, overwrite=args.overwrite,
                             match_distance=args.match_distance)
