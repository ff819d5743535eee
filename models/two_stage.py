"""Two-stage reduction gearbox: a topology the paper does not have, reduced by the same code.

Input pinion (gear1) -> wheel (gear2) = intermediate shaft = pinion (gear3) -> output
wheel (gear4). Two meshes with backlash, one torsional shaft: four inertias,
one rigid-body mode, three relative coordinates (x1 mesh 1, x2 shaft twist,
x3 mesh 2). Teeth z = 20/40/20/60, so the second mesh runs at z3/z2 = 1/2 of
the first mesh frequency and the forcing period is 4 pi in tau. Radii are
proportional to the teeth and inertias to r^2 (illustrative values).
"""
import sympy as sp

from gearsym import Drivetrain, Gear, Harmonic, Mesh, Shaft, Torque, rectangular_mesh_stiffness

model = Drivetrain("two_stage", title="Two-stage reduction gearbox (beyond the paper)")
g1 = model.add(Gear("gear1", inertia="I1", base_radius="r1"))
g2 = model.add(Gear("gear2", inertia="I2", base_radius="r2"))
g3 = model.add(Gear("gear3", inertia="I3", base_radius="r3"))
g4 = model.add(Gear("gear4", inertia="I4", base_radius="r4"))
model.add(Mesh("stage1", g1, g2, stiffness="kZ", damping="cZ", backlash="eta", coordinate="x1"))
model.add(Shaft("intermediate", g2, g3, stiffness="kS", coordinate="x2"))
model.add(Mesh(
    "stage2", g3, g4, stiffness="kZ2", damping="cZ2", backlash="eta2", coordinate="x3",
    variation=rectangular_mesh_stiffness("k_a2"), order=sp.Rational(1, 2),
    function="k2", damping_group="zeta2", stiffness_group="K2",
))
model.add(Torque("M1", on=g1, mean="M1", harmonics=(Harmonic("M1a", phase="Theta", group="B1"),)))
model.add(Torque("M4", on=g4, mean="M4", load=True))
model.set_defaults(
    omega=1.5, zeta=0.08, zeta2=0.08, K2=1.0, B0=1.0, B1=4.0, Theta=0.0, B0_x3=1.0,
    eta=10.0, eta2=10.0, kS=1.0, k_a=0.2, k_a2=0.2,
    I1=1.0, I2=4.0, I3=1.0, I4=9.0, r1=1.0, r2=2.0, r3=1.0, r4=3.0,
)
model.set_initial_state(x1=-2.0, v1=-0.5, x3=-2.0, v3=-0.5)
model.describe(
    K2="mean stiffness of the second mesh relative to the first",
    kS="torsional stiffness of the intermediate shaft",
)
