"""One-stage gear pair (the paper's Eq. 1, reduced to Eq. 2).

Two gear wheels joined by a mesh with periodic stiffness, damping and backlash;
gear 1 is driven by M1 = mean + harmonic (phase Theta), gear 2 carries the load M2.
The reduction derives x = r1 psi1 - r2 psi2 and the groups zeta, B0, B1 of Eq. 3.
"""
from gearsym import Drivetrain, Gear, Harmonic, Mesh, Torque

PAPER_VALUES = dict(omega=1.5, zeta=0.08, B0=1.0, B1=4.0, Theta=0.0, eta=10.0)


def build(name: str = "one_stage", resonant: bool = False) -> Drivetrain:
    """The gear pair; ``resonant=True`` adds the weak resonant torque D cos(tau + Theta_p) of Eq. 6."""
    title = "One-stage gear pair with a weak resonant term (Eq. 6)" if resonant else "One-stage gear pair (Eqs. 1-2)"
    m = Drivetrain(name, title=title)
    g1 = m.add(Gear("gear1", inertia="I1", base_radius="r1"))
    g2 = m.add(Gear("gear2", inertia="I2", base_radius="r2"))
    m.add(Mesh("mesh", g1, g2, stiffness="kZ", damping="cZ", backlash="eta"))
    harmonics = [Harmonic("M1a", phase="Theta", group="B1")]
    if resonant:
        harmonics.append(Harmonic("M1d", phase="Theta_p", group="D"))
    m.add(Torque("M1", on=g1, mean="M1", harmonics=tuple(harmonics)))
    m.add(Torque("M2", on=g2, mean="M2", load=True))
    m.set_defaults(**PAPER_VALUES, k_a=0.2)
    m.set_initial_state(x=-2.0, v=-0.5)  # the paper's start
    if resonant:
        m.set_defaults(D=2.0, Theta_p=0.1)
    m.describe(
        omega="forcing frequency (= mesh frequency) in units of omega_n",
        eta="backlash (clearance) in the length unit of x",
        k_a="relative amplitude of the mesh stiffness variation (gearsym default, not in the paper)",
        Theta="phase of the excitation",
        Theta_p="phase of the weak resonant term",
    )
    return m


model = build()
