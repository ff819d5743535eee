"""What each parameter of a drivetrain declared as a bare name is (an inertia of a body, a mesh's backlash, the
phase of a torque's harmonic): the description of a parameter the model does not describe itself."""
from __future__ import annotations

import sympy as sp

from .symbols import parameter_symbol, phi
from .expressions import parameter_names
from .resolved import ResolvedDrivetrain
from .stiffness import rectangular_mesh_stiffness


def default_wave_amplitude(variation: sp.Expr) -> str | None:
    """The amplitude parameter if ``variation`` is the default stiffness wave, else None."""
    names = sorted(parameter_names(variation) - {phi.name})
    if len(names) != 1:
        return None
    return names[0] if sp.expand(variation - rectangular_mesh_stiffness(names[0])) == 0 else None


def parameter_roles(rd: ResolvedDrivetrain) -> dict[str, str]:
    """What each parameter declared as a bare name is in the drivetrain: the description of one the model does not
    describe (the derivation pages', the systems' and so the FMUs')."""
    roles: dict[str, str] = {"omega": "forcing frequency (tau = omega t)"}

    def put(expr: sp.Expr, text: str) -> None:
        if isinstance(expr, sp.Symbol):
            roles.setdefault(expr.name, text)

    for rb in (*rd.bodies, *rd.fixed):  # (a held ring's radius is a parameter too)
        if rb.inertia is not None:
            put(rb.inertia, f"moment of inertia of {rb.body.name!r}")
        if rb.radius is not None:
            put(rb.radius, f"base radius of {rb.body.name!r}" + (" (held)" if rb.body.fixed else ""))
    for rb in rd.translations:  # (a body on bearings: its centre's mass)
        put(rb.inertia, f"mass of {rb.body.name!r}")
    for rc in rd.couplings:
        kind = {"mesh": "mean mesh", "bearing": "translational"}.get(rc.kind, "torsional")
        name = rc.component.name if rc.kind == "bearing" else rc.name  # (a bearing's x and y share its name)
        put(rc.stiffness, f"{kind} stiffness of {rc.kind} {name!r}")
        put(rc.damping, f"damping of {rc.kind} {name!r}")
        if rc.kind == "mesh":
            put(rc.backlash, f"backlash (clearance) of mesh {rc.name!r}")
            amplitude = default_wave_amplitude(rc.variation)
            if amplitude is not None:
                put(parameter_symbol(amplitude), f"relative amplitude of the stiffness variation of mesh {rc.name!r}")
    for f in rd.forcing:
        if f.order:
            put(f.phase, f"phase of the order-{f.order} harmonic of torque {f.torque.name!r}")
    return roles
