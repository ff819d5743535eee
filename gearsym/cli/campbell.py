"""``gearsym campbell MODEL --param speed=500rpm:9000rpm:50rpm``: the Campbell diagram beside the amplitude of
a sweep over the same speeds (the sweep is resumable, as ``gearsym sweep``'s)."""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from ..loading import natural_modes
from ..errors import GearsymError
from ..figures.campbell import plot_campbell
from ..files.atomic import write_atomically
from ..files.outputs import check_figure, check_file
from ..physical.campbell import campbell
from ..physical.files import write_physical_table
from ..physical.sweeps import nondimensional_axis
from ..opening import open_model
from ..options import Execution
from ..sweep import run_sweep
from ..sweep.grid import parse_axis
from ..sweep.store import sidecar
from .arguments.integration import add_integration_arguments, integration_from, model_request
from .arguments.settings import add_set_argument, refuse_swept_and_set

NAME = "campbell"
HELP = "Campbell diagram (natural frequencies, mesh and torque orders, crossings) beside the amplitude over speed"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("model", help="a model with physical values (see docs/units.md)")
    parser.add_argument("--param", required=True, metavar="SPEED=START:STOP:STEP",
                        help="the speed axis, e.g. speed=500rpm:9000rpm:50rpm")
    add_set_argument(parser)
    parser.add_argument("--orders", type=int, default=3, help="harmonics of the mesh frequency drawn (default 3)")
    add_integration_arguments(parser, periods=300, discard=200)
    parser.add_argument("--jobs", type=int, default=0, help="processes for the sweep (default 0: every core)")
    parser.add_argument("--out", type=Path, required=True, metavar="FILE.csv",
                        help="the amplitude sweep (resumed if it exists); FILE.physical.csv the same in the speed's unit, "
                             "um and 1/s; FILE.campbell.json holds the diagram")
    parser.add_argument("--plot", type=Path, required=True, metavar="FILE.png", help="the figure")
    parser.add_argument("--no-sweep", action="store_true", help="the diagram alone (no amplitude panel)")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")


def run(args: argparse.Namespace) -> int:
    check_file(args.out, (".csv",))
    check_figure(args.plot)
    if args.orders < 1:
        raise GearsymError(f"--orders must be at least 1, got {args.orders}")
    request = model_request(args, integration_from(args))
    model = open_model(request)
    scaling = model.scaling
    if scaling is None or not scaling.speed:
        raise GearsymError(f"{args.model}: a Campbell diagram needs physical values and a declared speed "
                           "(model.set_physical, Gear(..., teeth=N, speed='speed')); see docs/units.md")
    axis = parse_axis(args.param)
    if axis.name != scaling.speed.parameter:
        raise GearsymError(f"--param {args.param!r}: the Campbell diagram runs along the speed "
                           f"({scaling.speed.parameter}=...), not {axis.name}")
    refuse_swept_and_set([(axis.name, args.param)], args.set)
    engine_axis = nondimensional_axis(scaling.full, axis)  # (a speed without its unit is refused here)
    modes = natural_modes(scaling.full.model, **model.checked_settings)
    diagram = campbell(scaling.full, axis.values, axis.unit, modes, args.orders)
    write_atomically(sidecar(args.out, ".campbell.json"), json.dumps(diagram.as_dict(), indent=2) + "\n")
    print(f"{diagram.model}: natural frequencies " + ", ".join(f"{f:.6g} Hz" for f in diagram.natural_frequencies))
    for c in diagram.crossings:
        print(f"crossing: {c.order} meets {c.natural_frequency:.6g} Hz at {c.speed:.6g} {axis.unit}")
    sweep = None
    if not args.no_sweep:
        compiled = model.compiled()
        result = run_sweep(compiled, [engine_axis], options=compiled.integration,
                           out=args.out, execution=Execution(args.jobs, progress=not args.quiet))
        sweep = scaling.to_physical(result, given=[axis])
        print(f"in physical units: {write_physical_table(sweep, sidecar(args.out, '.physical.csv'))}")

    given = {name: f"{value:g}" if isinstance(value, float) else str(value) for name, value in args.set.items()}
    plot_campbell(diagram, args.plot, sweep, settings=given)
    print(f"gearsym: wrote {args.plot}", file=sys.stderr)
    return 0
