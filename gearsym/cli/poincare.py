"""``gearsym poincare MODEL``: Poincare maps from many random initial states, grouped into attractors."""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from ..analysis.attractors import DEFAULT_BOX, RUN, AttractorSet, check_ics, find_attractors
from ..checks import chosen_coordinate
from ..errors import GearsymError
from ..figures.poincare import plot_attractors
from ..files.outputs import check_figure
from ..opening import open_model
from .arguments.integration import add_integration_arguments, integration_from, model_request
from .arguments.settings import add_set_argument

NAME = "poincare"
HELP = "Poincare maps from many random initial states, grouped into coexisting attractors"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("model", help="a model name (see `gearsym list`) or the path of a model file")
    add_set_argument(parser)
    parser.add_argument("--ics", type=int, default=10, help="number of random initial states (default 10)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the random initial states (default 0)")
    parser.add_argument("--box", metavar="x=-5:5,v=-5:5",
                        help=f"where the initial states are drawn, per state (default {DEFAULT_BOX[0]:g}:"
                             f"{DEFAULT_BOX[1]:g} for every state not named)")
    add_integration_arguments(parser, **RUN)
    parser.add_argument("--format", choices=("text", "json"), default="text")
    parser.add_argument("--plot", type=Path, metavar="FILE.png",
                        help="also draw the Poincare points of every attractor")
    parser.add_argument("--coordinate", metavar="NAME",
                        help="the coordinate --plot shows (against the state after it; default the first)")


def parse_box(text: str | None) -> dict[str, tuple[float, float]] | None:
    """``x=-5:5,v=-2:2`` -> {'x': (-5.0, 5.0), 'v': (-2.0, 2.0)} (bounds are checked by find_attractors)."""
    if not text:
        return None
    box: dict[str, tuple[float, float]] = {}
    usage = f"--box {text!r}: expected NAME=LOW:HIGH pairs separated by commas, e.g. x=-5:5,v=-2:2"
    for item in text.split(","):
        name, sep, bounds = (part.strip() for part in item.partition("="))
        low, colon, high = bounds.partition(":")
        if not sep or not name or not colon:
            raise GearsymError(usage)
        if name in box:
            raise GearsymError(f"--box gives {name} twice")
        try:
            box[name] = (float(low), float(high))
        except ValueError:
            raise GearsymError(usage) from None
    return box


def run(args: argparse.Namespace) -> int:
    if args.plot:
        check_figure(args.plot)
    box = parse_box(args.box)
    options = integration_from(args)
    check_ics(args.ics, 1, options.periods)  # at least one state each: before the model is compiled
    request = model_request(args, options)
    compiled = open_model(request).compiled()
    coordinate = chosen_coordinate(args.coordinate, compiled.observed, args.plot)
    found = find_attractors(compiled, ics=args.ics, seed=args.seed, box=box)
    if args.plot:
        plot_attractors(found, args.plot, x=coordinate)
        print(f"gearsym: wrote {args.plot}", file=sys.stderr)
    if args.format == "json":
        print(json.dumps(found.as_dict(), indent=2))
    else:
        print(report(found))
    return 0


def report(found: AttractorSet) -> str:
    """The text output: the run, then each attractor, then where each initial state went."""
    box = ", ".join(f"{n} in [{lo:g}, {hi:g}]" for n, (lo, hi) in (found.box or {}).items())
    lines = [
        f"{found.model}: {len(found.results)} initial states ({box}, seed {found.seed}), "
        f"{found.discard} periods discarded, {found.measured} measured, {found.steps_per_period} RK4 steps/period, "
        f"{found.backend}",
        "parameters: " + ", ".join(f"{k}={v:g}" for k, v in found.parameters.items()),
        f"{len(found)} attractor{'s' if len(found) != 1 else ''} ('1' regular, '2' chaotic, as the paper marks them):",
    ]
    for a in found.attractors:
        members = " ".join(f"#{i}" for i in a.members)
        lines += [
            f"  attractor {a.number} ['{a.paper_label}'] {a.description}: "
            f"{len(a.members)} of {len(found.results)} initial states ({members})",
            f"    lambda_1 = {a.lambda1:+.6f} +- {a.lambda1_stderr:.6f}",
            "    amplitude " + ", ".join(f"A_{k} = {v:.6g}" for k, v in a.amplitude.items()),
            "    centroid  " + ", ".join(f"{k}={v:.6g}" for k, v in a.centroid.items()),
        ]
    lines.append("initial states:")
    for r in found.results:
        start = ", ".join(f"{k}={v:+.4f}" for k, v in r.initial_state.items())
        lines.append(f"  #{r.index:<3d} {start}  -> attractor {r.attractor}  (lambda_1 = {r.exponents[0]:+.5f}, "
                     f"{r.regime})")
    return "\n".join(lines)
