"""The spur pair on bearings: Kahraman & Singh's lateral-torsional gear pair, in physical units.

The gears are spur_pair's (the NASA Lewis gear-noise rig's 28-tooth gears, from their geometry: inertias, base
radii, the mesh stiffness kZ by the potential-energy method), now each on a bearing of stiffness k_b1, k_b2: each
centre translates, and the mesh deflection is the projection of both centres' motions and both rotations on the
line of action (Kahraman & Singh, J. Sound Vib. 146, 1991 and 142, 1990: r1 theta1 - r2 theta2 + y1 - y2 with y
along the line of action). ``dof=4`` (the default): each centre moves along the line of action only (the frame's
y axis is the line of action), 4 degrees of freedom; ``dof=6`` (``--set dof=6``): both directions, with the line
of centres along x, so the line of action is tilted by the pressure angle alpha and the bearing forces have the x
and y components a housing feels.

Sources and assumptions. From the rig's geometry (spur_pair): I1, I2, r1, r2, kZ, the masses m1, m2 of the gear
bodies (steel disks of the mean of tip and root diameters, 20 mm bore) and alpha = 20 deg. Ours: the bearing
stiffness 1e8 N/m (the planet-bearing stiffness of Lin & Parker's example, a typical rolling-element bearing), a
bearing damping of 2 % of critical on the gear's mass, the mesh damping, backlash, torques and speed of spur_pair.
"""
import math

from gearsym import Bearing, Drivetrain, Gear, Harmonic, Mesh, Torque

OPTIONS = {"dof": 4}  # model options: --set dof=6
TORQUE = 71.8  # N m on the pinion
DAMPING_RATIO = 0.05
BEARING_STIFFNESS = 1e8  # N/m
BEARING_DAMPING_RATIO = 0.02
NASA_RIG_GEAR = dict(teeth=28, module="3.175 mm", pressure_angle="20 deg", face_width="6.35 mm",
                     bore_diameter="20 mm")


def build(dof: int = 4) -> Drivetrain:
    """The pair on bearings with ``dof`` = 4 (centres along the line of action) or 6 (both directions)."""
    if dof not in (4, 6):
        raise ValueError(f"dof must be 4 (along the line of action) or 6 (both directions), got {dof!r}")
    model = Drivetrain("spur_pair_bearings", title=f"A spur gear pair on bearings, {dof} degrees of freedom "
                                                   "(NASA gear-noise rig geometry)")
    pinion = model.add(Gear.from_geometry("pinion", inertia="I1", base_radius="r1", mass="m1", speed="speed",
                                          **NASA_RIG_GEAR))
    wheel = model.add(Gear.from_geometry("wheel", inertia="I2", base_radius="r2", mass="m2", **NASA_RIG_GEAR))
    along = dof == 4
    model.add(Mesh.from_gears("mesh", pinion, wheel, stiffness="kZ", damping="cZ", backlash="eta", coordinate="x",
                              pressure_angle="alpha", centres="alpha" if along else 0))
    directions = "y" if along else "xy"
    model.add(Bearing("bearing1", pinion, stiffness="k_b1", damping="c_b1", directions=directions))
    model.add(Bearing("bearing2", wheel, stiffness="k_b2", damping="c_b2", directions=directions))
    model.add(Torque("M1", on=pinion, mean="M1", harmonics=(Harmonic("M1a", phase="Theta", group="B1"),)))
    model.add(Torque("M2", on=wheel, mean="M2", load=True))
    g1, g2 = pinion.geometry, wheel.geometry
    effective_mass = 1 / (g1.base_radius**2 / g1.polar_inertia + g2.base_radius**2 / g2.polar_inertia)
    damping = 2 * DAMPING_RATIO * math.sqrt(model.physical["kZ"].si * effective_mass)
    model.set_physical(
        alpha="20 deg",
        k_b1=f"{BEARING_STIFFNESS:g} N/m", k_b2=f"{BEARING_STIFFNESS:g} N/m",
        c_b1=f"{2 * BEARING_DAMPING_RATIO * math.sqrt(BEARING_STIFFNESS * g1.mass):.9g} N*s/m",
        c_b2=f"{2 * BEARING_DAMPING_RATIO * math.sqrt(BEARING_STIFFNESS * g2.mass):.9g} N*s/m",
        cZ=f"{damping:.9g} N*s/m", eta="100 um",
        M1=f"{TORQUE} N*m", M2=f"{TORQUE} N*m", M1a=f"{0.1 * TORQUE:.9g} N*m", Theta=0,
        speed="6000 rpm",
    )
    model.set_initial_state(x=1.0)
    model.describe(
        speed="speed of the pinion",
        m1="pinion mass (from its geometry: the steel disk of the mean of tip and root diameters, 20 mm bore)",
        m2="wheel mass (as the pinion's)",
        I1="pinion inertia (from its geometry)", I2="wheel inertia (from its geometry)",
        r1="pinion base radius (from its geometry)", r2="wheel base radius (from its geometry)",
        alpha="pressure angle (the line of action's tilt from the common tangent of the pitch circles)",
        k_b1="pinion bearing stiffness (assumed: 1e8 N/m)", k_b2="wheel bearing stiffness (assumed: 1e8 N/m)",
        c_b1="pinion bearing damping (2 % of critical on the pinion's mass)",
        c_b2="wheel bearing damping (2 % of critical on the wheel's mass)",
        kZ="mean mesh stiffness, computed from the pair's geometry (potential-energy method)",
        cZ="mesh damping for a damping ratio of 0.05",
        eta="backlash along the line of action",
        M1a="torque fluctuation at the mesh frequency (10 % of the mean)",
    )
    return model


model = build()
