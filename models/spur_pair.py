"""A spur gear pair in physical units: the worked example of docs/units.md.

The gear geometry is that of the NASA Lewis gear-noise rig's test gears as its reports describe them
(e.g. Liou, Lin, Oswald & Townsend, *Effect of Contact Ratio on Spur Gear Dynamic Load*, NASA TM 105606,
1992): a 1:1 pair of 28-tooth spur gears, module 3.175 mm (8 diametral pitch), 20 degree pressure angle,
6.35 mm face width. The mesh stiffness and the resonance it gives come from ISO 6336-1 (method B): the
mean mesh stiffness c_gamma_alpha = 20 N/(mm um) per unit face width, and the main resonance speed
n_E1 = 30000/(pi z1) sqrt(c_gamma_alpha/m_red). Our assumptions (not from either source): the gear
bodies are solid steel disks of the pitch diameter, a backlash of 100 um, a damping ratio of 0.05, a
torque fluctuation of 10 % of the mean torque at the mesh frequency, and gearsym's default stiffness
variation. docs/units.md compares the result with ISO 6336-1's resonance speed and ranges.
"""
import math

from gearsym import Drivetrain, Gear, Harmonic, Mesh, Torque

TEETH = 28
MODULE = 3.175e-3  # m (8 diametral pitch)
PRESSURE_ANGLE = math.radians(20.0)
FACE_WIDTH = 6.35e-3  # m
STEEL = 7850.0  # kg/m^3
MESH_STIFFNESS_PER_WIDTH = 20.0  # N/(mm um): ISO 6336-1's c_gamma_alpha for solid steel spur gears
TORQUE = 71.8  # N m on the pinion
DAMPING_RATIO = 0.05

pitch_radius = TEETH * MODULE / 2
base_radius = pitch_radius * math.cos(PRESSURE_ANGLE)
inertia = 0.5 * STEEL * math.pi * pitch_radius**4 * FACE_WIDTH  # a solid disk of the pitch diameter
stiffness = MESH_STIFFNESS_PER_WIDTH * FACE_WIDTH * 1e9  # N/m: N/(mm um) x mm
effective_mass = 1 / (2 * base_radius**2 / inertia)  # of the pair along the line of action
damping = 2 * DAMPING_RATIO * math.sqrt(stiffness * effective_mass)

model = Drivetrain("spur_pair", title="A spur gear pair in physical units (NASA gear-noise rig geometry)")
pinion = model.add(Gear("pinion", inertia="I1", base_radius="r1", teeth=TEETH, speed="speed"))
wheel = model.add(Gear("wheel", inertia="I2", base_radius="r2", teeth=TEETH))
model.add(Mesh("mesh", pinion, wheel, stiffness="kZ", damping="cZ", backlash="eta"))
model.add(Torque("M1", on=pinion, mean="M1", harmonics=(Harmonic("M1a", phase="Theta", group="B1"),)))
model.add(Torque("M2", on=wheel, mean="M2", load=True))
model.set_physical(
    I1=f"{inertia:.9g} kg*m^2", I2=f"{inertia:.9g} kg*m^2",
    r1=f"{base_radius * 1e3:.9g} mm", r2=f"{base_radius * 1e3:.9g} mm",
    kZ=f"{stiffness:.9g} N/m", cZ=f"{damping:.9g} N*s/m", eta="100 um",
    M1=f"{TORQUE} N*m", M2=f"{TORQUE} N*m", M1a=f"{0.1 * TORQUE:.9g} N*m", Theta=0, k_a=0.2,
    speed="6000 rpm",
)
model.set_initial_state(x=1.0)  # at the static deflection (the length unit)
model.describe(
    speed="speed of the pinion",
    I1="pinion inertia (a solid steel disk of the pitch diameter)",
    I2="wheel inertia (as the pinion's)",
    kZ="mean mesh stiffness, ISO 6336-1's 20 N/(mm um) x face width",
    cZ="mesh damping for a damping ratio of 0.05",
    eta="backlash along the line of action",
    M1a="torque fluctuation at the mesh frequency (10 % of the mean)",
)
