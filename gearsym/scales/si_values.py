"""A drivetrain's physical values in SI without its reduction: what its natural modes need.

The modes of a drivetrain on bearings need only its kinematics and its parameters' values (masses, inertias,
radii, stiffnesses, angles), not the reduced equations a :class:`~gearsym.scales.map.Scaling` is made from.
Values are read and checked here as the scaling reads them: each a quantity with the dimension its role
(:mod:`.roles`) gives, a plain number only for a dimensionless one.
"""
from __future__ import annotations

from collections.abc import Mapping

from ..errors import ModelError, UnknownParameterError
from ..units import dimension_text, measure
from .dimensions import same_dimension
from .roles import parameter_roles, physical_parameters
from .settings import maybe_number
from .speeds import declared_speed


def si_values(drivetrain, settings: Mapping[str, object]) -> dict[str, float]:
    """Every physical value of ``drivetrain`` (declared, ``settings`` overriding) in SI, checked against its role."""
    rd = drivetrain.resolved
    roles = parameter_roles(rd)
    speed = declared_speed(drivetrain)
    known = set(physical_parameters(rd)) | ({speed.parameter} if speed else set())
    given = dict(drivetrain.physical)
    for name, value in settings.items():
        if name not in known:
            raise UnknownParameterError(name, sorted(known), f"{drivetrain.name}: physical values")
        given[name] = measure(maybe_number(value), f"{drivetrain.name}: {name}")
    out = {}
    for name, q in given.items():
        role = roles.get(name, (None, ""))[0]
        if role is not None and role.example and not same_dimension(q.dims, role.dims):
            raise ModelError(f"{q.text()} is not {role.describe()} (it is {dimension_text(q.dims)})",
                             f"{drivetrain.name}: {name}")
        out[name] = q.si
    for name, value in drivetrain.defaults.items():
        if name not in out and isinstance(value, (int, float)) and not isinstance(value, bool):
            out[name] = float(value)
    return out
