"""``gearsym stiffness --teeth 28,28 --module "3.175 mm" --face-width "6.35 mm" --pressure-angle "20 deg"``: the
mesh stiffness of a gear pair from its geometry over one mesh period, with ISO 6336-1's numbers beside it."""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np

from ..errors import GearsymError
from ..figures.stiffness import plot_cracked_mesh, plot_mesh_stiffness
from ..geometry import (ORIGINS, GearGeometry, GearPair, Material, crack_loss_along_path, cracked_mesh_stiffness,
                        loss_against_depth, mesh_stiffness, root_crack, STEEL)
from ..files.outputs import check_figure
from ..geometry.gear import ISO53_FILLET
from ..units import parse_quantity, Quantity, shown

NAME = "stiffness"
HELP = ("mesh stiffness of a gear pair from its geometry (potential-energy method) over one mesh period, contact "
        "ratios, and ISO 6336-1's c', c_gamma_alpha")

#: rows of the curve in the text output (the JSON has every sample)
TEXT_ROWS = 36


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--teeth", required=True, metavar="Z1,Z2", help="tooth counts of gear 1 (driving) and gear 2")
    parser.add_argument("--module", required=True, metavar="M", help='normal module with its unit, e.g. "3 mm"')
    parser.add_argument("--face-width", required=True, metavar="B", help='face width, e.g. "20 mm"')
    parser.add_argument("--pressure-angle", required=True, metavar="A", help='normal pressure angle, e.g. "20 deg"')
    parser.add_argument("--profile-shift", default="0,0", metavar="X1,X2",
                        help="profile shift coefficients (in modules; default 0,0)")
    parser.add_argument("--helix-angle", default=None, metavar="H", help='helix angle, e.g. "15 deg" (default: spur)')
    parser.add_argument("--bore", default=None, metavar="D1,D2",
                        help='bore diameters, e.g. "20 mm,30 mm" or one for both (default: solid gears)')
    parser.add_argument("--centre-distance", default=None, metavar="A",
                        help="working centre distance (default: no backlash at the profile shifts' distance)")
    parser.add_argument("--rack", default=None, metavar="HA,HF,RHO",
                        help="the basic rack's addendum, dedendum and tip-rounding radius in modules (default "
                             "1,1.25,0.38: ISO 53 profile A, where its rounding fits the pressure angle; else, as "
                             "at 25 deg, the largest rounding that fits, a full-round tip; profile D is 1,1.4,0.39)")
    parser.add_argument("--material", default=None, metavar="E,NU",
                        help='Young\'s modulus and Poisson\'s ratio of both gears, e.g. "206 GPa,0.3" (default steel)')
    parser.add_argument("--slices", type=int, default=None, help="slices of a helical pair's face width (default 20)")
    parser.add_argument("--format", choices=("text", "json"), default="text")
    parser.add_argument("--plot", type=Path, default=None, metavar="FILE.png",
                        help="the curve, its contact zones, its mean and ISO's (with --crack: the mesh stiffness while "
                             "the cracked tooth passes, beside the healthy curve, and the loss against crack depth)")
    parser.add_argument("--crack", default=None, metavar="DEPTH,ANGLE",
                        help='a root crack on one tooth of --cracked-gear, e.g. "3 mm,70 deg": its depth and its angle '
                             "to the tooth's centre line, from ISO 6336-3's critical section (--crack-origin)")
    parser.add_argument("--cracked-gear", type=int, choices=(1, 2), default=2,
                        help="the gear whose tooth is cracked (1: driving, 2: driven; default 2)")
    parser.add_argument("--crack-origin", choices=ORIGINS, default="critical_section",
                        help="where the crack starts: ISO 6336-3's critical section (the 30 deg tangent, default) or "
                             "the base circle (Tian 2004)")


def _split(text: str, option: str, count: int | None = 2) -> list[str]:
    parts = [p.strip() for p in text.split(",")]
    if any(not p for p in parts) or (count is not None and len(parts) != count):
        want = f"{count} values separated by a comma" if count else "values separated by commas"
        raise GearsymError(f"{option} {text!r}: expected {want}")
    return parts


#: what each SI unit a quantity is read in measures, for the messages
_KINDS = {"m": "a length", "Pa": "a pressure (Young's modulus)", "rad": "an angle"}


def _quantity(text: str, option: str, unit: str, example: str):
    """``text`` as a pint Quantity convertible to ``unit`` (pint is imported here, not at start-up)."""
    import pint


    q = parse_quantity(text, option)
    if str(q.units) == "dimensionless":
        raise GearsymError(f"{option} {text!r} has no unit; give one, e.g. {example}")
    try:
        q.to(unit)
    except pint.DimensionalityError:
        raise GearsymError(f"{option} {text!r} is not {_KINDS[unit]}; e.g. {example}") from None
    return q


def _number(text: str, option: str, whole: bool = False):
    try:
        value = int(text) if whole else float(text)
    except ValueError:
        raise GearsymError(f"{option}: {text!r} is not a {'whole number' if whole else 'number'}") from None
    if not whole and not math.isfinite(value):
        raise GearsymError(f"{option}: {text!r} is not a finite number")
    return value


def _geometry(args):
    """The two gears and the pair from the options, and the user's length unit (the module's)."""
    z1, z2 = (_number(t, "--teeth", whole=True) for t in _split(args.teeth, "--teeth"))
    module = _quantity(args.module, "--module", "m", '"3 mm"')
    face = _quantity(args.face_width, "--face-width", "m", '"20 mm"')
    alpha = _quantity(args.pressure_angle, "--pressure-angle", "rad", '"20 deg"')
    x1, x2 = (_number(t, "--profile-shift") for t in _split(args.profile_shift, "--profile-shift"))
    beta = _quantity(args.helix_angle, "--helix-angle", "rad", '"15 deg"') if args.helix_angle else None
    bores = [0.0, 0.0]
    if args.bore:
        texts = _split(args.bore, "--bore", None)
        if len(texts) > 2:
            raise GearsymError(f"--bore {args.bore!r}: expected one diameter or two separated by a comma")
        bores = [_quantity(t, "--bore", "m", '"20 mm"').to("m").magnitude for t in texts]
        bores = bores * 2 if len(bores) == 1 else bores
    material = STEEL
    if args.material:
        E_text, nu_text = _split(args.material, "--material")
        E = _quantity(E_text, "--material", "Pa", '"206 GPa,0.3"').to("Pa").magnitude
        material = Material(E=E, nu=_number(nu_text, "--material (Poisson's ratio)"), rho=STEEL.rho)
    centre = _quantity(args.centre_distance, "--centre-distance", "m", '"100 mm"').to("m").magnitude \
        if args.centre_distance else None
    helix = beta.to("rad").magnitude if beta is not None else 0.0
    # (no --rack: ISO 53 profile A, or the largest rounding that fits where 0.38 does not: GearGeometry's default)
    ha, hf, rho = (_number(t, "--rack") for t in _split(args.rack, "--rack", 3)) if args.rack else (1.0, 1.25, None)
    common = dict(module=module.to("m").magnitude, pressure_angle=alpha.to("rad").magnitude,
                  face_width=face.to("m").magnitude, material=material, addendum_coefficient=ha,
                  dedendum_coefficient=hf, fillet_coefficient=rho)
    gear1 = GearGeometry(teeth=z1, profile_shift=x1, helix_angle=helix, bore_diameter=bores[0], **common)
    gear2 = GearGeometry(teeth=z2, profile_shift=x2, helix_angle=-helix, bore_diameter=bores[1], **common)
    described = [f"{z1}/{z2} teeth", f"module {_shown(module)}", f"pressure angle {_shown(alpha)}",
                 f"face width {_shown(face)}"]
    if x1 or x2:
        described.append(f"profile shift {x1:g}/{x2:g}")
    if beta is not None and helix:
        described.append(f"helix angle {_shown(beta)}")
    rho = gear1.fillet_coefficient
    if (ha, hf, rho) != (1.0, 1.25, ISO53_FILLET):
        full_round = math.isclose(rho, gear1.largest_fillet_coefficient, rel_tol=1e-9)
        described.append(f"rack {ha:g}/{hf:g}/{rho:.3g}{' (full-round tip)' if full_round else ''}")
    if args.bore:
        described.append("bore " + "/".join(_shown(_quantity(t, '--bore', 'm', '"20 mm"')) for t in _split(args.bore, "--bore", None)))
    return GearPair(gear1, gear2, centre), ", ".join(described), module.units


def _shown(q) -> str:
    return shown(q)


def run(args: argparse.Namespace) -> int:
    if args.plot is not None:
        check_figure(args.plot)
    pair, title, length_unit = _geometry(args)
    crack = _crack(args, pair)
    result = mesh_stiffness(pair, slices=args.slices)
    cracked = _cracked(pair, args.cracked_gear, crack) if crack is not None else None
    if args.format == "json":
        data = result.as_dict()
        data["pair"] = title
        data["rack"] = _rack_dict(pair.gear1)
        data["gears"] = [_gear_dict(g) for g in (pair.gear1, pair.gear2)]
        data["units"]["gears"] = "m, kg, kg m^2"
        data["units"]["rack"] = "modules"
        if cracked is not None:
            data["crack"] = cracked
            data["units"]["crack"] = "m, rad, fractions of the pair's stiffness; phase in rad"
        print(json.dumps(data, indent=1))
    else:
        _print_text(result, pair, title, length_unit)
        if cracked is not None:
            _print_crack(cracked, args.crack, length_unit)
    if args.plot is not None:
        if crack is None:
            plot_mesh_stiffness(result, args.plot, title)
        else:
            plot_cracked_mesh(pair, args.cracked_gear, crack, cracked, args.plot, f"{title}; crack {args.crack} on "
                              f"a tooth of gear {args.cracked_gear}, from {crack.origin.replace('_', ' ')}")
        print(f"gearsym: wrote {args.plot}", file=sys.stderr)
    return 0


#: samples of the mesh stiffness while the cracked tooth passes, and of the loss against depth
_PASSAGE_POINTS = 481
_DEPTHS = 25


def _crack(args, pair):
    """The crack of ``--crack``, checked against the pair before any work (None without one)."""
    if args.crack is None:
        return None
    depth_text, angle_text = _split(args.crack, "--crack")
    depth = _quantity(depth_text, "--crack (its depth)", "m", '"3 mm,70 deg"').to("m").magnitude
    angle = _quantity(angle_text, "--crack (its angle)", "rad", '"3 mm,70 deg"').to("rad").magnitude
    crack = root_crack(depth, angle, origin=args.crack_origin)
    if pair.gear1.helix_angle:
        raise GearsymError("--crack: the root crack model is for spur pairs (Tian; Chen & Shao); drop --helix-angle")
    gear = pair.gear1 if args.cracked_gear == 1 else pair.gear2
    crack.path(gear.profile)  # (a crack through the tooth is refused here)
    return crack


def _cracked(pair, gear: int, crack) -> dict:
    """The crack's loss along the path, the mesh stiffness while its tooth passes, and its mean loss against depth
    (from 0 to just short of the unloaded flank, at its angle), JSON-ready."""
    loss = crack_loss_along_path(pair, gear, crack.depth, crack.angle, origin=crack.origin,
                                 limit_line=crack.limit_line)
    e = pair.contact_ratio
    phase = 2 * math.pi * np.linspace(-0.5, e + 0.5, _PASSAGE_POINTS)
    healthy, cracked = cracked_mesh_stiffness(pair, gear, crack, phase)
    depths, means, crossing = loss_against_depth(pair, gear, crack, _DEPTHS)
    return {"depth": crack.depth, "angle": crack.angle, "origin": crack.origin, "limit_line": crack.limit_line,
            "gear": gear, "mean_loss": loss.mean, "path_fraction": loss.fraction.tolist(), "loss": loss.loss.tolist(),
            "phase": phase.tolist(), "healthy": healthy.tolist(), "cracked": cracked.tolist(),
            "depths": depths.tolist(), "mean_losses": means.tolist(), "centre_line_depth": crossing}


def _print_crack(cracked: dict, text: str, length_unit) -> None:
    loss = np.array(cracked["loss"])
    print(f"crack {text} on a tooth of gear {cracked['gear']} from {cracked['origin'].replace('_', ' ')}: its pair "
          f"loses {100 * cracked['mean_loss']:.4g} % of its stiffness averaged over the path of contact "
          f"({100 * loss.min():.3g} % to {100 * loss.max():.3g} % along it)")


def _rack_dict(gear) -> dict:
    return {"addendum": gear.addendum_coefficient, "dedendum": gear.dedendum_coefficient,
            "tip_rounding": gear.fillet_coefficient, "said": gear.rack}


def _gear_dict(gear) -> dict:
    return {"teeth": gear.teeth, "base_diameter": 2 * gear.base_radius, "tip_diameter": 2 * gear.tip_radius,
            "root_diameter": 2 * gear.root_radius, "mass": gear.mass, "polar_inertia": gear.polar_inertia}


def _print_text(result, pair, title: str, length_unit) -> None:
    def length(value_m: float) -> str:
        return f"{Quantity(value_m, 'm').to(length_unit).magnitude:.6g} {length_unit:~P}"

    print(title)
    print(f"contact ratio: transverse {result.contact_ratio:.6g}, overlap {result.overlap_ratio:.6g}, "
          f"total {result.contact_ratio + result.overlap_ratio:.6g}")
    print(f"centre distance {length(pair.centre_distance)}, working pressure angle "
          f"{math.degrees(pair.working_pressure_angle):.6g} deg")
    for i, gear in enumerate((pair.gear1, pair.gear2), 1):
        print(f"gear {i}: base diameter {length(2 * gear.base_radius)}, tip {length(2 * gear.tip_radius)}, "
              f"root {length(2 * gear.root_radius)}; body {gear.mass:.6g} kg, {gear.polar_inertia:.6g} kg m^2")
    print(f"basic rack (both gears): {pair.gear1.rack}")
    sliced = f" ({result.slices} slices)" if result.slices > 1 else ""
    print(f"mesh stiffness{sliced}: mean {result.mean:.6g} N/m, min {result.min:.6g} N/m, max {result.max:.6g} N/m")
    zones = "; ".join(f"{z.pairs} pair{'s' if z.pairs != 1 else ''} for phase {z.start:.4g}-{z.end:.4g} rad"
                      for z in result.zones)
    print(f"zones{' (mid-face section)' if result.overlap_ratio > 0 else ''}: {zones}")
    iso = result.iso6336
    print(f"ISO 6336-1 method B, N/(mm um): c'_th {iso.theoretical:.6g}, c' {iso.single:.6g}, "
          f"c_gamma_alpha {iso.mesh_alpha:.6g}, c_gamma_beta {iso.mesh_beta:.6g} (c_gamma_alpha b = "
          f"{iso.mean_stiffness:.6g} N/m)")
    print("curve over one mesh period:")
    print(f"{'phase [rad]':>12}  {'k [N/m]':>12}")
    step = max(1, len(result.phase) // TEXT_ROWS)
    for phi, k in zip(result.phase[::step], result.stiffness[::step]):
        print(f"{phi:>12.5g}  {k:>12.6g}")
