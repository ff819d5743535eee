"""Gears from their geometry: dimensions, contact ratios, gear bodies, and the mesh stiffness over a mesh period.

Below the model stage: it imports nothing of gearsym but its errors and small checks, and works in SI floats
(m, Pa, kg/m^3, rad). The face functions here also take pint Quantities (converted to SI on entry, without
importing pint); strings with units are read at the edge above (the ``gearsym stiffness`` command).

    gear = gear_geometry(teeth=28, module=3.175e-3, pressure_angle=math.radians(20), face_width=6.35e-3)
    pair = gear_pair(gear, gear)                  # centre distance, contact ratios, path of contact
    k = mesh_stiffness(pair)                      # MeshStiffness: k(phi) in N/m, mean, zones, ISO 6336-1
    k.fourier(7)                                  # mean and cos/sin coefficients of k / mean

The method, its validity and the comparison with ISO 6336: docs/geometry.md.
"""
from __future__ import annotations

from ..errors import GearsymError
from .crack import LIMIT_LINES, ORIGINS, Crack
from .crack_loss import CrackLoss, cracked_mesh_stiffness, loss_against_depth
from .crack_loss import crack_loss_along_path as _crack_loss_along_path
from .crack_loss import crack_stiffness_loss as _crack_stiffness_loss
from .foundation import BODY_RATIO_RANGE, ROOT_ANGLE_RANGE
from .gear import GearGeometry
from .iso6336 import Iso6336Stiffness, iso6336_stiffness
from .material import STEEL, Material
from .meshing import Fourier, MeshStiffness, StiffnessOptions, Zone
from .meshing import mesh_stiffness as _mesh_stiffness
from .pair import GearPair
from .tooth_pair import TERMS, pair_compliances, pair_stiffness

__all__ = ["BODY_RATIO_RANGE", "Crack", "CrackLoss", "LIMIT_LINES", "ORIGINS", "crack_loss_along_path",
           "crack_stiffness_loss", "cracked_mesh_stiffness", "loss_against_depth", "root_crack", "Fourier", "GearGeometry", "GearPair", "Iso6336Stiffness", "Material",
           "MeshStiffness", "ROOT_ANGLE_RANGE", "STEEL", "StiffnessOptions", "TERMS", "Zone", "gear_geometry",
           "gear_pair", "iso6336_stiffness", "mesh_stiffness", "pair_compliances", "pair_stiffness"]

#: each length and angle parameter of gear_geometry and the SI unit a pint Quantity is converted to
_UNITS = {"module": "m", "face_width": "m", "bore_diameter": "m", "pressure_angle": "rad", "helix_angle": "rad"}


def _si(value, unit: str, name: str):
    """A float in ``unit`` from a float or anything with pint's ``to`` (a Quantity); no pint import here."""
    if hasattr(value, "to") and hasattr(value, "magnitude"):
        try:
            return float(value.to(unit).magnitude)
        except Exception as exc:  # pint's DimensionalityError, or an array
            raise GearsymError(f"gear: {name} = {value} is not in {unit} ({exc})") from None
    if isinstance(value, str):
        raise GearsymError(f"gear: {name} = {value!r} is text; give a number in {unit} or a pint Quantity "
                           "(the gearsym stiffness command reads text with units)")
    return value


def gear_geometry(*, teeth: int, module, pressure_angle, face_width, profile_shift: float = 0.0, helix_angle=0.0,
                  addendum_coefficient: float = 1.0, dedendum_coefficient: float = 1.25,
                  fillet_coefficient: float | None = None, bore_diameter=0.0, material: Material = STEEL) -> GearGeometry:
    """A :class:`GearGeometry`; lengths in m and angles in rad, or pint Quantities in any unit of the kind."""
    values = {"module": module, "face_width": face_width, "bore_diameter": bore_diameter,
              "pressure_angle": pressure_angle, "helix_angle": helix_angle}
    si = {name: _si(value, _UNITS[name], name) for name, value in values.items()}
    return GearGeometry(teeth=teeth, profile_shift=profile_shift, addendum_coefficient=addendum_coefficient,
                        dedendum_coefficient=dedendum_coefficient, fillet_coefficient=fillet_coefficient,
                        material=material, **si)


def gear_pair(gear1: GearGeometry, gear2: GearGeometry, centre_distance=None) -> GearPair:
    """A :class:`GearPair` (gear 1 drives); ``centre_distance`` in m or a Quantity, None for no backlash."""
    if centre_distance is not None:
        centre_distance = _si(centre_distance, "m", "centre distance")
    return GearPair(gear1, gear2, centre_distance)


def mesh_stiffness(pair: GearPair, options: StiffnessOptions | None = None, *, line_load: float | None = None,
                   **option_values) -> MeshStiffness:
    """The mesh stiffness of ``pair`` over one mesh period (:class:`MeshStiffness`); how it is computed is
    ``options`` or the :class:`StiffnessOptions` fields as keywords (``slices=40``, ``terms=("hertz",)``)."""
    if option_values:
        if options is not None:
            raise GearsymError("mesh stiffness: give options or option keywords, not both")
        try:
            options = StiffnessOptions(**option_values)
        except TypeError:
            known = ", ".join(StiffnessOptions.__dataclass_fields__)
            raise GearsymError(f"mesh stiffness: unknown option among {', '.join(option_values)}; "
                               f"the options are {known}") from None
    return _mesh_stiffness(pair, options, line_load=line_load)


def root_crack(depth, angle, *, origin: str = "critical_section", limit_line: str = "parallel") -> Crack:
    """A root :class:`Crack` (:mod:`.crack`): ``depth`` in m and ``angle`` (from the tooth's centre line) in rad, or
    pint Quantities; ``origin`` where it starts (ISO 6336-3's critical section, or Tian's base circle)."""
    return Crack(_si(depth, "m", "crack depth"), _si(angle, "rad", "crack angle"), origin, limit_line)


def crack_stiffness_loss(pair: GearPair, gear: int, depth, angle, *, origin: str = "critical_section",
                         limit_line: str = "parallel") -> float:
    """The fraction of its pair's stiffness a root crack on a tooth of gear ``gear`` (1: the pair's driving gear, 2)
    takes away, averaged over the path of contact (:mod:`.crack`): ``depth`` in m and ``angle`` (from the tooth's
    centre line) in rad, or pint Quantities. It is the depth of a constant :class:`gearsym.ToothFault` on that tooth;
    :func:`crack_loss_along_path` gives the loss along the path, which :func:`gearsym.cracked_tooth` puts in a model."""
    return _crack_stiffness_loss(pair, gear, _si(depth, "m", "crack depth"), _si(angle, "rad", "crack angle"),
                                 origin=origin, limit_line=limit_line)


def crack_loss_along_path(pair: GearPair, gear: int, depth, angle, *, origin: str = "critical_section",
                          limit_line: str = "parallel") -> CrackLoss:
    """The :class:`CrackLoss` of a root crack on a tooth of gear ``gear`` of ``pair``: its loss of the pair's
    stiffness along the path of contact, its mean, and the shape a model carries it with (lengths in m or
    Quantities, as :func:`crack_stiffness_loss`)."""
    return _crack_loss_along_path(pair, gear, root_crack(depth, angle, origin=origin, limit_line=limit_line))
