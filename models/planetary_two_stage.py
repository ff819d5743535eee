"""Two-stage gearbox: the planetary stage of models/planetary.py, its carrier driving a parallel stage.

Sun input, ring held, three planets; the carrier turns the pinion of a parallel gear pair through a
flexible shaft, and the wheel carries the load. Nine bodies less one rigid-body mode: eight coordinates
(four independent planetary mesh deflections, the shaft twist, the parallel mesh); the ring meshes of
planets 2 and 3 close loops as in the one-stage set. The pinion has 47 teeth, so the parallel mesh runs
at 47/94 = 1/2 of the planetary mesh frequency and the forcing period is 4 pi in tau. Values are
illustrative (nondimensional): the parallel pair's radii in proportion to its teeth (47/94) and the
shaft as stiff as the meshes.
"""
import sympy as sp

from gearsym import Gear, Mesh, Shaft, Torque, rectangular_mesh_stiffness
from models.planetary import INERTIAS, RADII, RING_TEETH, build, carrier_inertia

PINION_TEETH, WHEEL_TEETH = 47, 94

model = build(name="planetary_two_stage", title="Planetary stage driving a parallel stage (sun in, ring held, wheel out)",
              carrier_load=False)
carrier = "carrier"
pinion = model.add(Gear("pinion", inertia="I_1", base_radius="r_1", teeth=PINION_TEETH))
wheel = model.add(Gear("wheel", inertia="I_2", base_radius="r_2", teeth=WHEEL_TEETH))
model.add(Shaft("output_shaft", carrier, pinion, stiffness="kS", coordinate="x_s"))
model.add(Mesh("parallel", pinion, wheel, stiffness="kZ_2", damping="cZ_2", backlash="eta_2", coordinate="z",
               variation=rectangular_mesh_stiffness("k_a"), order=sp.Rational(PINION_TEETH, RING_TEETH),
               function="k_2", damping_group="zeta_2", stiffness_group="K_2"))
model.add(Torque("M_w", on=wheel, mean="M_w", load=True))
PARALLEL = dict(I_1=1.0, I_2=16.0, r_1=1.0, r_2=2.0)  # radii in proportion to the teeth, inertias ~ r^4


def balanced_load() -> dict:
    """Torques in balance that deflect each planetary mesh, the shaft and the parallel mesh by the length unit:
    the sun's M_s as in models/planetary.py, the carrier's (1 + Z_r/Z_s) M_s through the shaft (kS), the
    wheel's load M_w = that times r_2/r_1 (K_2), a torque fluctuation of a fifth of M_s (B1)."""
    r_s, r_p, r_r = RADII["r_s"], RADII["r_p"], RADII["r_r"]
    sun_line = r_s**2 / INERTIAS["I_s"] + r_p**2 / INERTIAS["I_p"] + (r_s + r_p) ** 2 / carrier_inertia(3)
    m_s = 3 * r_s / sun_line
    m_c = m_s * (r_s + r_r) / r_s
    p = PARALLEL
    m_w = m_c * p["r_2"] / p["r_1"]
    return dict(B0=m_s * r_s / INERTIAS["I_s"], B1=0.2 * m_s * r_s / INERTIAS["I_s"], B0_z=m_w * p["r_2"] / p["I_2"],
                kS=p["r_1"] * m_c, K_2=m_c / p["r_1"] * (p["r_1"] ** 2 / p["I_1"] + p["r_2"] ** 2 / p["I_2"]))


model.set_defaults(**PARALLEL, **balanced_load(), zeta_2=0.05, eta_2=1.0)
model.describe(kS="torsional stiffness of the shaft from the carrier to the pinion",
               K_2="mean stiffness of the parallel mesh relative to a sun-planet mesh")
