"""``gearsym simulate MODEL``: synthetic measurements (a tidy CSV) from a model, with noise."""
from __future__ import annotations

import argparse
from pathlib import Path

import gearsym  # the face: the code generator loads on first use

from ..data.simulate import RUN, simulate_measurements, steps_for
from ..errors import GearsymError
from ..fit.effects import augment, effect
from ..fit.shaft_effects import is_shaft_effect
from ..files.outputs import check_file
from ..loading import load
from ..opening import open_model
from .arguments.integration import add_integration_arguments, integration_from, model_request
from .arguments.settings import add_set_argument, model_settings, parse_numbers, parse_state

NAME = "simulate"
HELP = "synthetic measurements of a model (tau, record, conditions, coordinates) with noise, as CSV"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("model", help="a model name (see `gearsym list`) or the path of a model file")
    add_set_argument(parser)
    parser.add_argument("--record", action="append", default=[], metavar="omega=1.2,B1=4",
                        help="one record and its operating conditions, written as columns of the file (repeat for "
                             "several records; default one record without conditions). --set values are the "
                             "simulated model and are not written")
    parser.add_argument("--samples-per-period", type=int, default=50,
                        help="samples per forcing period (default 50); must divide the RK4 steps per period")
    add_integration_arguments(parser, **RUN, steps_help="RK4 steps per period (default: the smallest multiple of the "
                                                       "samples per period of at least 200)")
    parser.add_argument("--noise", type=float, default=0.0,
                        help="Gaussian noise, standard deviation relative to the clean signal's, per record and "
                             "column (0.01 = 1 %%; default 0)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the noise (default 0)")
    parser.add_argument("--velocities", action="store_true", help="also write the velocity states (v, v1, ...)")
    parser.add_argument("--y0", metavar="x=-2,v=-0.5", help="initial state of every record (default: the model's)")
    parser.add_argument("--effect", action="append", default=[], metavar="NAME",
                        help="simulate the model with an effect of the library added (coulomb_friction, "
                             "nonlinear_damping, cubic_stiffness, hertzian_contact, coast_side_stiffness, "
                             "shaft_damping, or a harmonic with its order: mesh_stiffness_harmonic_3, "
                             "torque_harmonic_2, transmission_error_1, or on a gear with --teeth: tooth_fault_GEAR "
                             "with --set q_GEAR and tooth_GEAR, eccentricity_GEAR with e_c_GEAR, e_s_GEAR; then "
                             "--periods and --discard count the gear's revolutions); set its strength with --set, "
                             "e.g. --effect cubic_stiffness --set k3=0.02")
    parser.add_argument("--out", type=Path, required=True, metavar="FILE.csv", help="where to write the measurements")


def run(args: argparse.Namespace) -> int:
    records = [parse_conditions(text) for text in args.record]
    y0 = parse_state(args.y0)  # (before the model is compiled)
    settings = model_settings(args)
    options = integration_from(args, steps_for(args.samples_per_period, args.steps_per_period), exponents=False)
    request = model_request(args, options, settings=settings)
    check_file(args.out, (".csv",))
    check_strengths([e for e in args.effect if not is_shaft_effect(e)], settings)  # (shaft-order ones: on the model)
    if args.effect:  # (the model with the effects added: a system of this run's own, compiled as it is)
        compiled = gearsym.compile_model(with_effects(request.model, args.effect, settings), options,
                                         verbose=request.verbose)
    else:
        compiled = open_model(request).compiled()
    table = simulate_measurements(compiled, samples_per_period=args.samples_per_period,
                                  noise=args.noise, seed=args.seed, records=records or None,
                                  y0=y0, velocities=args.velocities, out=args.out)
    per_record = table.rows // table.records
    conditions = f"; conditions {', '.join(table.conditions)}" if table.conditions else ""
    cycles = compiled.cycles  # (a period of several forcing periods: a gear's revolution)
    unit = "period" if cycles == 1 else "forcing period"
    periods = "periods" if cycles == 1 else f"periods of {cycles} forcing periods"
    print(f"{table.model}: {table.records} record(s) of {per_record} samples ({table.samples_per_period} per {unit}, "
          f"{options.measured} {periods} after {args.discard} discarded, {table.steps_per_period} RK4 steps/{unit}), "
          f"noise {args.noise:g}{conditions}; columns {', '.join(table.columns)}")
    print(f"wrote {args.out}")
    return 0


def with_effects(model: str, effects: list[str], settings: dict):
    """The model's equations with ``effects`` added; ``settings`` set the model's and the effects' parameters (a
    shaft-order effect is found on the gears of the model, with --teeth's counts)."""
    geared = load(model, teeth=settings.get("teeth"))
    chosen = [effect(e, geared) for e in effects]
    check_strengths(chosen, settings)
    own = {p for e in chosen for p in e.parameters}
    base = load(model, **{k: v for k, v in settings.items() if k not in own})
    return augment(base, chosen, values={k: v for k, v in settings.items() if k in own})


def check_strengths(effects: list[str], settings: dict) -> None:
    """Every effect needs a strength other than 0 (its off value) among ``settings``."""
    for e in (effect(name) for name in effects):
        if not any(_nonzero(settings.get(p)) for p in e.fitted):
            given = " and/or ".join(f"--set {p}=VALUE" for p in e.fitted)
            raise GearsymError(f"--effect {e.name} needs its strength: {given} (the effect is off at 0, which "
                               f"would simulate the model without it)")


def _nonzero(value: str | None) -> bool:
    try:
        return value is not None and float(value) != 0.0
    except ValueError:
        raise GearsymError(f"an effect's strength must be a number, got {value!r}") from None


def parse_conditions(text: str) -> dict[str, float]:
    """``omega=1.2,B1=4`` -> {'omega': 1.2, 'B1': 4.0} (numbers only: a record's operating conditions)."""
    return parse_numbers(text, "--record", "omega=1.2,B1=4")
