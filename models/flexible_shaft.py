"""Gear pair with a disk on a flexible shaft (the paper's Eq. 8, reduced to Eq. 9).

The reduction derives x1 = r1 psi1 - r2 psi2, x2 = r2 (psi3 - psi2), the groups
beta1..beta3 and the torque-balance condition of Eq. 10. The paper does not
give the inertias and radii behind beta1..beta3, so they are declared here with
default value 1 (beta1 = 1, beta2 = 2, beta3 = 1/2); change them with --set.
"""
from gearsym import Disk, Drivetrain, Gear, Harmonic, Mesh, Shaft, Torque
from models.one_stage import PAPER_VALUES

model = Drivetrain("flexible_shaft", title="Gear pair with a flexible shaft and disk (Eqs. 8-10)")
g1 = model.add(Gear("gear1", inertia="I1", base_radius="r1"))
g2 = model.add(Gear("gear2", inertia="I2", base_radius="r2"))
d3 = model.add(Disk("disk3", inertia="I3"))
model.add(Mesh("mesh", g1, g2, stiffness="kZ", damping="cZ", backlash="eta", coordinate="x1"))
model.add(Shaft("shaft", g2, d3, stiffness="kS", coordinate="x2", forced=False))  # the torque balance of Eq. 10
model.add(Torque("M1", on=g1, mean="M1", harmonics=(Harmonic("M1a", phase="Theta", group="B1"),)))
model.add(Torque("M2", on=g2, mean="M2", load=True))
model.add(Torque("M3", on=d3, mean="M3", load=True))
model.set_defaults(**PAPER_VALUES, kS=0.1, k_a=0.2, I1=1.0, I2=1.0, I3=1.0, r1=1.0, r2=1.0)
model.set_initial_state(x1=-2.0, v1=-0.5)  # the paper's start
model.describe(
    kS="torsional stiffness of the shaft (the paper's coupling; 0, 0.1, 1.0 in Fig. 6)",
    I1="inertia of gear 1 (not given in the paper)",
    I2="inertia of gear 2 (not given in the paper)",
    I3="inertia of the disk (not given in the paper)",
    r1="base radius of gear 1 (not given in the paper)",
    r2="base radius of gear 2 (not given in the paper)",
)
