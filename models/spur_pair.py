"""A spur gear pair in physical units, declared from its geometry: the worked example of docs/units.md.

The gear geometry is that of the NASA Lewis gear-noise rig's test gears as its reports describe them
(e.g. Liou, Lin, Oswald & Townsend, *Effect of Contact Ratio on Spur Gear Dynamic Load*, NASA TM 105606,
1992): a 1:1 pair of 28-tooth spur gears, module 3.175 mm (8 diametral pitch), 20 degree pressure angle,
6.35 mm face width, ISO 53's basic rack (profile A), steel. From it gearsym computes the gears' bodies (disks of
the mean of tip and root diameters with their bore), their base radii, and the mesh stiffness over one mesh
period by the potential-energy method (docs/geometry.md), which enters the model as its mean (kZ, N/m) times
its Fourier series in the mesh phase (7 harmonics, Lanczos-smoothed). Our assumptions (not from the sources): a
20 mm bore in each gear (inside the range of Sainsot's body formula), a backlash of 100 um, a damping ratio of
0.05, a torque fluctuation of 10 % of the mean torque at the mesh frequency. docs/units.md compares the result
with ISO 6336-1's mesh stiffness and resonance speed, which the model used before.
"""
import math

from gearsym import Drivetrain, Gear, Harmonic, Mesh, Torque

TORQUE = 71.8  # N m on the pinion
DAMPING_RATIO = 0.05
NASA_RIG_GEAR = dict(teeth=28, module="3.175 mm", pressure_angle="20 deg", face_width="6.35 mm",
                     bore_diameter="20 mm")

model = Drivetrain("spur_pair", title="A spur gear pair in physical units (NASA gear-noise rig geometry)")
pinion = model.add(Gear.from_geometry("pinion", inertia="I1", base_radius="r1", speed="speed", **NASA_RIG_GEAR))
wheel = model.add(Gear.from_geometry("wheel", inertia="I2", base_radius="r2", **NASA_RIG_GEAR))
mesh = model.add(Mesh.from_gears("mesh", pinion, wheel, stiffness="kZ", damping="cZ", backlash="eta"))
model.add(Torque("M1", on=pinion, mean="M1", harmonics=(Harmonic("M1a", phase="Theta", group="B1"),)))
model.add(Torque("M2", on=wheel, mean="M2", load=True))

# the damping for the damping ratio at the computed mean stiffness and the pair's effective mass
effective_mass = 1 / (pinion.geometry.base_radius**2 / pinion.geometry.polar_inertia
                      + wheel.geometry.base_radius**2 / wheel.geometry.polar_inertia)
damping = 2 * DAMPING_RATIO * math.sqrt(model.physical["kZ"].si * effective_mass)
model.set_physical(
    cZ=f"{damping:.9g} N*s/m", eta="100 um",
    M1=f"{TORQUE} N*m", M2=f"{TORQUE} N*m", M1a=f"{0.1 * TORQUE:.9g} N*m", Theta=0,
    speed="6000 rpm",
)
model.set_initial_state(x=1.0)  # at the static deflection (the length unit)
model.describe(
    speed="speed of the pinion",
    I1="pinion inertia (from its geometry: a steel disk of the mean of tip and root diameters, 20 mm bore)",
    I2="wheel inertia (as the pinion's)",
    r1="pinion base radius (from its geometry)",
    r2="wheel base radius (from its geometry)",
    kZ="mean mesh stiffness, computed from the pair's geometry (potential-energy method)",
    cZ="mesh damping for a damping ratio of 0.05",
    eta="backlash along the line of action",
    M1a="torque fluctuation at the mesh frequency (10 % of the mean)",
)
