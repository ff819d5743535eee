"""``gearsym spectrum MODEL``: the order spectrum of a simulated run or of measured records, with the mesh
harmonics and each gear's shaft-order sidebands labelled; a figure and JSON.

    gearsym spectrum one_stage --teeth 20,53 --effect tooth_fault_gear2 --set q_gear2=0.3 --set tooth_gear2=7 \\
        --out spectrum.json --plot spectrum.png
    gearsym spectrum one_stage --teeth 20,53 --data measured.csv --out spectrum.json --plot spectrum.png
"""
from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

import gearsym  # the face: the code generator loads on first use

from ..analysis.order_run import SAMPLES_PER_CYCLE, mesh_gears, simulated_order_spectrum
from ..analysis.orders import MESH_HARMONICS, MIN_REVOLUTIONS, SIDEBANDS, check_length, most_sidebands, order_spectrum
from ..checks import check_fits, json_safe
from ..data.measurements import load_measurements
from ..errors import GearsymError
from ..files.atomic import write_atomically
from ..figures.orders import plot_order_spectra
from ..loading import declared, split_options
from ..opening import OpenModel, open_model
from ..options import STEPS_PER_PERIOD, Integration
from ..files.outputs import check_figure, check_file
from ..physical.point import LENGTH
from .arguments.integration import add_integration_arguments, check_run, model_request
from .arguments.settings import add_set_argument, model_settings
from .simulate import with_effects

NAME = "spectrum"
#: the shortest default run, in mesh periods (small gears: 4 revolutions would not part a period-2 response's half
#: orders from their sidebands)
MIN_MESH_PERIODS = 200
HELP = "order spectrum (mesh harmonics and each gear's shaft-order sidebands) of a run or of measured records"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("model", help="a model name (see `gearsym list`) or the path of a model file")
    add_set_argument(parser)
    parser.add_argument("--effect", action="append", default=[], metavar="NAME",
                        help="simulate with an effect of the library added, as for `gearsym simulate` "
                             "(tooth_fault_GEAR, eccentricity_GEAR, ...)")
    parser.add_argument("--data", nargs="+", type=Path, default=None, metavar="FILE.csv",
                        help="the spectra of measured records instead of a run (every record and channel; tau or t "
                             "with --time-scale, as for `gearsym explain`)")
    parser.add_argument("--time-scale", type=float, default=None, help="tau = TIME_SCALE * t for a file with t")
    parser.add_argument("--coordinate", metavar="NAME", help="the mesh coordinate of a run (default the first "
                                                             "geared mesh's)")
    parser.add_argument("--mesh-harmonics", type=int, default=MESH_HARMONICS, metavar="M",
                        help=f"mesh harmonics labelled (default {MESH_HARMONICS})")
    parser.add_argument("--sidebands", type=int, default=SIDEBANDS, metavar="K",
                        help=f"shaft orders labelled on each side of each (default {SIDEBANDS})")
    add_integration_arguments(parser, periods=None)
    parser.add_argument("--periods", type=int, default=None,
                        help="periods of the run in all (default: 4 revolutions of the slower gear, and at least "
                             f"{MIN_MESH_PERIODS} mesh periods, after the transient)")
    parser.add_argument("--discard", type=int, default=None, help="transient periods (default: 100 mesh periods)")
    parser.add_argument("--out", type=Path, default=None, metavar="FILE.json", help="the spectra and their lines")
    parser.add_argument("--plot", type=Path, default=None, metavar="FILE.png", help="the figure")
    parser.add_argument("--quiet", action="store_true")


def run(args: argparse.Namespace) -> int:
    for option, value in (("--mesh-harmonics", args.mesh_harmonics), ("--sidebands", args.sidebands)):
        if value < 1:
            raise GearsymError(f"{option} must be at least 1, got {value}")
    if args.out:
        check_file(args.out, (".json",))
    if args.plot:
        check_figure(args.plot)
    settings = model_settings(args)
    request = model_request(args, settings=settings)  # (the run's options: from the model's tooth counts)
    model = open_model(request)
    if args.data:
        spectra, what = _measured(args, model)
    else:
        spectra, what = _simulated(args, model)
    for s in spectra:
        strongest = sorted((ln for ln in s.lines if ln.gear and math.isfinite(ln.amplitude)),
                           key=lambda ln: -ln.amplitude)[:3]
        energy = ", ".join(f"{g} {s.sideband_energy(g):.3g}" for g in s.gears)
        unit = f" {s.unit}" if s.unit else ""  # (a physical model: its label in the user's values, not the engine's)
        print(f"{s.info.get('label') or s.title}: {s.length:.4g} mesh periods; sideband energy {energy}; strongest "
              + ", ".join(f"{ln.label} ({ln.order:.4g}) {ln.amplitude:.3g}{unit}" for ln in strongest))
    if args.out:
        write_atomically(args.out, json.dumps(json_safe({"model": args.model, "source": what,
                                                          "spectra": [s.as_dict() for s in spectra]}), indent=1) + "\n")
        print(f"wrote {args.out}")
    if args.plot:
        gears = ", ".join(f"{g} {z} teeth" for g, z in spectra[0].gears.items())
        labels = [s.info.get("label", "") for s in spectra]
        plot_order_spectra(spectra, args.plot, title=f"Order spectrum of {what} (model {args.model}: {gears})",
                           labels=labels if any(labels) else None, max_order=args.mesh_harmonics + 0.5)
        print(f"wrote {args.plot}")
    return 0


def _check_sidebands(args, gears: dict) -> None:
    """--sidebands K: at most the sidebands a gear has of its own (k < Z/2; the default is cut to them per gear)."""
    most = max(most_sidebands(z) for z in gears.values())
    if args.sidebands > most and args.sidebands != SIDEBANDS:
        raise GearsymError(f"--sidebands {args.sidebands}: a gear of Z teeth has Z/2 sidebands of its own on each side "
                           f"of a mesh harmonic (beyond, they are the next harmonic's); here at most {most} "
                           f"({', '.join(f'{g} {z} teeth' for g, z in gears.items())})")


#: memory per sample of a run's order spectrum: the samples and the windowed fit's columns (two copies)
def _spectrum_bytes(lines: int) -> int:
    return 8 * (2 + 2 * (1 + 2 * lines))


def _simulated(args, model: OpenModel):
    settings = model.request.settings
    _check_periods_declared(args, settings)
    system = with_effects(args.model, args.effect, settings) if args.effect else model.system
    name, gears, _ = mesh_gears(system, args.coordinate)
    _check_sidebands(args, gears)
    cycles = system.cycles
    discard = _discard(args, cycles)
    measured = max(1, math.ceil(max(4 * max(gears.values()), MIN_MESH_PERIODS) / cycles))
    periods = args.periods if args.periods is not None else discard + measured
    steps = args.steps_per_period or STEPS_PER_PERIOD
    teeth = ", ".join(f"{g} {z} teeth" for g, z in gears.items())
    if args.periods is None:  # (the run's length comes from the tooth counts: say so, not --periods)
        asked = (f"the default run of {teeth} (4 revolutions of the larger gear, {measured * cycles} mesh periods, "
                 "after the transient)")
    else:
        asked = f"--periods {args.periods}"
        _check_periods(args, gears, cycles)
    lines = args.mesh_harmonics * (1 + 2 * len(gears) * args.sidebands) + len(gears) * args.sidebands
    samples = SAMPLES_PER_CYCLE * cycles
    check_fits(periods, 16 * steps * cycles * (len(system.states) + 1) + (periods - discard) / periods * samples
               * _spectrum_bytes(lines), asked=asked, item="period", what="the run's every step, its samples and the "
               "fit of the lines")
    check_run(steps_per_period=steps)
    options = Integration(periods=periods, discard=discard, steps_per_period=steps, locate_crossings=not args.plain,
                          backend=args.backend)
    if args.effect:  # (the model with the effects added: a system of this run's own, compiled as it is)
        compiled = gearsym.compile_model(system, options, verbose=model.request.verbose)
    else:
        compiled = model.compiled(options)
    scale, unit, values = _unit(model, name)
    s = simulated_order_spectrum(compiled, coordinate=name, mesh_harmonics=args.mesh_harmonics,
                                 sidebands=args.sidebands, scale=scale, unit=unit)
    if unit:  # a physical model: its title in the user's values (the engine's numbers stay in the JSON's title)
        given = ", ".join(f"{k}={v}" for k, v in settings.items()) or "its declared values"
        span = s.title.split(";")[0].split(": ", 1)[1]
        s.info["label"] = (f"{system.name} at {given}: {span}, {compiled.steps_per_cycle} "
                           f"{compiled.integration.method_name} steps per mesh period")
        s.info["parameters"] = values  # (every physical value as given: the title's are the engine's numbers)
    return [s], f"a run of {system.name}" + (f" ({', '.join(args.effect)})" if args.effect else "")


def _discard(args, cycles: int) -> int:
    """--discard, or by default 100 mesh periods."""
    return args.discard if args.discard is not None else max(1, math.ceil(100 / cycles))


def _check_periods(args, gears: dict, cycles: int) -> None:
    """--periods (minus --discard) holds MIN_REVOLUTIONS revolutions of every gear of ``gears`` (periods of
    ``cycles`` mesh periods each)."""
    discard = _discard(args, cycles)
    check_length((args.periods - discard) * cycles, gears, f"the run of --periods {args.periods} minus --discard "
                 f"{discard} ({cycles} mesh period{'s' if cycles > 1 else ''} each)",
                 f"give at least --periods {discard + math.ceil(MIN_REVOLUTIONS * max(gears.values()) / cycles)}")


def _check_periods_declared(args, settings: dict) -> None:
    """--periods too short for any mesh's sidebands, refused from the model's declaration (its tooth counts and
    period: a second) before it is reduced and compiled (minutes for a large model). The mesh the run will show
    is known only after the reduction (a planet's second mesh closes a loop): the run is refused here when it is
    too short for every mesh with tooth counts, and checked again against its own mesh once it is known. A run
    with --effect is checked then only (a tooth fault lengthens the period)."""
    if args.periods is None or args.effect:
        return
    options, _ = split_options(args.model, {k: v for k, v in settings.items() if k != "teeth"})
    model = declared(args.model, settings.get("teeth"), options)
    if not model.is_drivetrain:
        return
    resolved = model.resolved
    meshes = [{end.body.name: end.body.tooth_count for end in (rc.a, rc.b)} for rc in resolved.couplings
              if rc.kind == "mesh" and rc.a.body.tooth_count and rc.b.body.tooth_count]
    if meshes:  # (the mesh whose sidebands need the shortest run)
        _check_periods(args, min(meshes, key=lambda gears: max(gears.values())), resolved.cycles)


def _unit(model: OpenModel, name: str) -> tuple[float, str, dict]:
    """The factor and unit of a run's coordinate in the model's physical units (µm for a mesh's deflection, rad
    for a shaft's twist) and its physical values as given, or (1, "", {}) for a model without physical values."""
    scaling = model.scaling
    if scaling is None:
        return 1.0, "", {}
    units = scaling.point_units()
    if units.kinds.get(name) == LENGTH:
        return units.per_unit[name] * units.m_to_length, units.length_text.text, dict(units.values)
    return units.per_unit.get(name, 1.0), units.radian.text, dict(units.values)


def _measured(args, model: OpenModel):
    if args.effect:
        raise GearsymError("--effect simulates a run; --data analyses measured records: give one of them")
    system = model.system
    _, gears, mesh_order = mesh_gears(system)
    _check_sidebands(args, gears)
    data = load_measurements(args.data, system, time_scale=args.time_scale)
    for r in data:  # (every record checked before any is analysed)
        length = mesh_order * float(r.tau[-1] - r.tau[0]) / (2 * math.pi)
        check_length(length, gears, f"{r.label}", "give a longer record, or leave its gears' sidebands to a longer one")
    spectra = []
    for r in data:
        for channel, values in r.observed.items():
            spectra.append(order_spectrum(r.tau, values, gears, mesh_order=mesh_order, channel=channel,
                                          mesh_harmonics=args.mesh_harmonics, sidebands=args.sidebands,
                                          title=f"{r.label}, {channel}"))
    return spectra, ", ".join(p.name for p in data.sources)
