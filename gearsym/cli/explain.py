"""``gearsym explain DATA.csv --model MODEL --fit zeta,B1 --out DIR``: what the data say the model lacks."""
from __future__ import annotations

import argparse
from pathlib import Path

from ..errors import GearsymError
from ..figures.fit_report import explain_files
from ..fit.selection import check_fit_names, check_harmonics
from ..files.outputs import check_folder
from ..options import Execution
from ..opening import OpenModel, open_model
from .arguments.integration import add_integration_arguments, integration_from, model_request
from .arguments.settings import add_set_argument

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
                        help="tau = TIME_SCALE * t, for files with a physical time column t (default for a model "
                             "with physical values: its omega_n in rad/s, so t is in seconds)")
    parser.add_argument("--held-out", type=float, default=0.25,
                        help="fraction of each record (its last whole periods) held out for judging (default 0.25)")
    parser.add_argument("--effects", default=None, metavar="NAME,NAME",
                        help="candidate effects (default: the whole library); a harmonic family's bare name "
                             "(torque_harmonic) stands for its orders 1 ... --harmonics, or name one (torque_harmonic_2); "
                             "with --teeth a shaft-order kind (tooth_fault, spall, eccentricity, spacing_errors) for "
                             "every gear's, and tooth_stiffness, tooth_profile for the tooth-by-tooth forms")
    parser.add_argument("--harmonics", type=int, default=None, metavar="N",
                        help="highest order of the harmonic families and of the proposals' harmonics (default 4)")
    parser.add_argument("--channel", action="append", default=[], metavar="NAME=FORMULA",
                        help="a column that measures a combination, e.g. acc=x1_ddot+0.5*x2_ddot (states, their "
                             "derivatives x_dot and x_ddot, the time and parameters)")
    parser.add_argument("--bias", default=None, metavar="CHANNEL,CHANNEL",
                        help="channels with an unknown constant offset fitted with the parameters (default: the "
                             "acceleration channels, x_ddot: bounded motion has zero mean acceleration, so an offset "
                             "is the sensor's bias; none: no offset)")
    parser.add_argument("--add-term", action="append", default=[], metavar="EXPR",
                        help="a term c*EXPR added to dv/dtau of the mesh coordinate, tried as an effect (a proposal "
                             "of report.json, or your own; g is the mesh's g(x, eta)); repeat for several")
    add_integration_arguments(parser, periods=None, steps_help="RK4 steps per forcing period between the samples "
                                                               "(default 200; the fit's windows are plain RK4)")
    parser.add_argument("--quiet", action="store_true")


def run(args: argparse.Namespace) -> int:
    fit = check_fit_names([p.strip() for p in args.fit.split(",") if p.strip()])  # before the model is reduced
    if args.harmonics is not None:
        check_harmonics(args.harmonics)
    candidates = [e.strip() for e in args.effects.split(",")] if args.effects else None
    bias = None if args.bias is None else [c.strip() for c in args.bias.split(",") if c.strip() not in ("", "none")]
    channels = dict(_channel(text) for text in args.channel)
    request = model_request(args, integration_from(args))
    check_folder(args.out)  # before the model is reduced (seconds)
    model = open_model(request)
    report = explain_files(args.data, model.system, fit, out=args.out, time_scale=_time_scale(args, model),
                           held_out=args.held_out, candidates=candidates, execution=Execution(progress=not args.quiet),
                           options=request.options,
                           channels=channels, bias=bias, terms=args.add_term, harmonics=args.harmonics)
    added = ", ".join(report["effects"]) or "none"
    print(f"{report['verdict']}: effects added: {added}; held-out error {report['error_before']:.4g} -> "
          f"{report['error_after']:.4g}; unexplained: {'yes' if report['unexplained'] else 'no'}")
    if report.get("bias_by_default"):
        offsets = ", ".join(f"{c} {report['bias'][c]:.4g}" for c in report["bias_by_default"])
        print(f"offset fitted by default (an acceleration's steady mean is zero for bounded motion): {offsets}; "
              "--bias none fits none")
    for p in report["proposed"][:1]:
        print(f"proposed beyond the library: {p['term']} (held-out error {p['held_out_error']:.4g}); try it with "
              f"--add-term \"{p['term']}\"")
    print(f"wrote {args.out / 'report.md'} and report.json")
    return 0


def _time_scale(args: argparse.Namespace, model: OpenModel) -> float | None:
    """--time-scale, or for a model with physical values its time unit: tau = omega_n t with t in seconds."""
    if args.time_scale is not None:
        return args.time_scale
    scaling = model.scaling
    return None if scaling is None else float(scaling.full.omega_n.to("rad/s").magnitude)


def _channel(text: str) -> tuple[str, str]:
    name, sep, formula = text.partition("=")
    if not sep or not name.strip() or not formula.strip():
        raise GearsymError(f"--channel {text!r}: write NAME=FORMULA, e.g. --channel acc=x1_ddot+0.5*x2_ddot")
    return name.strip(), formula.strip()
