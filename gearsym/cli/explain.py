"""``gearsym explain DATA.csv --model MODEL --fit zeta,B1 --out DIR``: what the data say the model lacks."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .integration import add_integration_arguments, integration_from, system_from
from .settings import add_set_argument

NAME = "explain"
HELP = "fit a model to measured data, find the missing physical effect, add it, report the error before and after"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("data", nargs="+", type=Path, help="measured-data CSV files (see docs/data-loop.md)")
    parser.add_argument("--model", required=True, help="the model to start from (name or path)")
    add_set_argument(parser)
    parser.add_argument("--fit", required=True, metavar="zeta,B1",
                        help="the model's parameters to estimate (the effects' own are added when tried)")
    parser.add_argument("--out", type=Path, required=True, metavar="DIR",
                        help="where report.md, report.json, the figures and derived_model.md go")
    parser.add_argument("--time-scale", type=float, default=None,
                        help="tau = TIME_SCALE * t, for files with a physical time column t")
    parser.add_argument("--held-out", type=float, default=0.25,
                        help="fraction of each record (its last whole periods) held out for judging (default 0.25)")
    parser.add_argument("--effects", default=None, metavar="NAME,NAME",
                        help="candidate effects (default: the whole library)")
    add_integration_arguments(parser, periods=None, steps_help="RK4 steps per forcing period between the samples "
                                                               "(default 200; the fit's windows are plain RK4)")
    parser.add_argument("--quiet", action="store_true")


def run(args: argparse.Namespace) -> int:
    from ..fit import explain_files
    from ..outputs import check_folder

    fit = [p.strip() for p in args.fit.split(",") if p.strip()]
    candidates = [e.strip() for e in args.effects.split(",")] if args.effects else None
    say = None if args.quiet else (lambda m: print(f"gearsym: {m}", file=sys.stderr, flush=True))
    options = integration_from(args)
    check_folder(args.out)  # before the model is reduced (seconds)
    report = explain_files(args.data, system_from(args), fit, out=args.out, time_scale=args.time_scale,
                           held_out=args.held_out, candidates=candidates, progress=say, options=options)
    added = ", ".join(report["effects"]) or "none"
    print(f"effects added: {added}; held-out error {report['error_before']:.4g} -> {report['error_after']:.4g}; "
          f"unexplained: {'yes' if report['unexplained'] else 'no'}")
    print(f"wrote {args.out / 'report.md'} and report.json")
    return 0
