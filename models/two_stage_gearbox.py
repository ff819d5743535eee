"""A motor on a flexible coupling driving a two-stage spur gearbox, declared from its geometry (issue 38).

The most common drivetrain there is, as a user writes it from the docs: an electric motor (150 N m at 1500 rpm,
about 24 kW) drives the first pinion through a flexible coupling; a 23/61 stage (module 2 mm, 20 mm face) and a
19/47 stage (module 3 mm, 30 mm face), both ISO 53 profile A, 20 deg, steel, with bores; the second stage's wheel
drives the load through the output shaft. Six bodies, one rigid-body mode: five coordinates, ten states (the
coupling's twist, the first mesh, the intermediate shaft's twist, the second mesh, the output shaft's twist).

Nothing about the meshes is typed by hand: the orders (the second mesh turns at 19/61 of the first's frequency),
the stiffness functions and their groups follow from the tooth counts, the mesh stiffness of each stage (mean and
7 Lanczos-smoothed harmonics, potential-energy method) from its geometry (docs/geometry.md). The model repeats
every 61 mesh periods of the first stage, and the engine counts its steps per mesh period of the first stage.

From the issue: the tooth counts, modules, face widths, the shaft stiffnesses (coupling 5e4, intermediate 2e5,
output 5e5 N m/rad), the torque and the speed. Our assumptions (typical values, not from a source): the bores
(25, 40, 30 and 50 mm), the motor's rotor inertia (0.2 kg m^2, an IEC 4-pole motor of this power) and the load's
(2 kg m^2 at the output shaft), a damping ratio of 0.05 in each mesh and in the (elastomer) coupling and 0.02 in
each steel shaft, each in its own torsional mode (the train on either side of it rigid), and the backlash (80 um in the first stage, 120 um in the
second: ISO 21771 normal backlash of the order of 0.04 modules).
"""
import math

from gearsym import Disk, Drivetrain, Gear, Mesh, Shaft, Torque

SPEED, TORQUE = "1500 rpm", 150.0  # motor speed, N m
STAGE1 = dict(module="2 mm", pressure_angle="20 deg", face_width="20 mm")
STAGE2 = dict(module="3 mm", pressure_angle="20 deg", face_width="30 mm")
MOTOR_INERTIA, LOAD_INERTIA = 0.2, 2.0  # kg m^2 (assumed)
SHAFTS = {"coupling": 5e4, "intermediate": 2e5, "output": 5e5}  # N m/rad (the issue's)
MESH_DAMPING, COUPLING_DAMPING, SHAFT_DAMPING = 0.05, 0.05, 0.02  # damping ratios (assumed)

model = Drivetrain("two_stage_gearbox", title="Motor, flexible coupling and a two-stage spur gearbox (23/61, 19/47)")
motor = model.add(Disk("motor", inertia="I_m", speed="speed"))
gear1 = model.add(Gear.from_geometry("gear1", teeth=23, bore_diameter="25 mm", **STAGE1))
gear2 = model.add(Gear.from_geometry("gear2", teeth=61, bore_diameter="40 mm", **STAGE1))
gear3 = model.add(Gear.from_geometry("gear3", teeth=19, bore_diameter="30 mm", **STAGE2))
gear4 = model.add(Gear.from_geometry("gear4", teeth=47, bore_diameter="50 mm", **STAGE2))
load = model.add(Disk("load", inertia="I_L"))
model.add(Shaft("coupling", motor, gear1, stiffness="k_c", damping="c_c"))
stage1 = model.add(Mesh.from_gears("stage1", gear1, gear2, stiffness="kZ1", damping="cZ1", backlash="eta1"))
model.add(Shaft("intermediate", gear2, gear3, stiffness="k_i", damping="c_i"))
stage2 = model.add(Mesh.from_gears("stage2", gear3, gear4, stiffness="kZ2", damping="cZ2", backlash="eta2"))
model.add(Shaft("output", gear4, load, stiffness="k_o", damping="c_o"))
model.add(Torque("M_m", on=motor, mean="M_m"))
model.add(Torque("M_L", on=load, mean="M_L", load=True))


def _inertia(gear) -> float:
    return gear.geometry.polar_inertia


def _mesh_damping(mesh, a, b) -> float:
    """The damping for the mesh's damping ratio at its mean stiffness and the pair's effective mass."""
    mass = 1 / (a.geometry.base_radius**2 / _inertia(a) + b.geometry.base_radius**2 / _inertia(b))
    return 2 * MESH_DAMPING * math.sqrt(model.physical[str(mesh.stiffness)].si * mass)


def _shaft_damping(ratio: float, stiffness: float, before: float, after: float) -> float:
    """The damping for the damping ratio ``ratio`` in the shaft's own torsional mode: the train on either side
    of it held rigid, ``before`` and ``after`` its inertias reflected to the shaft's speed."""
    return 2 * ratio * math.sqrt(stiffness * before * after / (before + after))


I1, I2, I3, I4 = (_inertia(g) for g in (gear1, gear2, gear3, gear4))
R1, R2 = 23 / 61, 19 / 47  # the stages' speed ratios
SIDES = {  # each shaft's two sides, reflected to its speed
    "coupling": (MOTOR_INERTIA, I1 + (I2 + I3) * R1**2 + (I4 + LOAD_INERTIA) * (R1 * R2)**2),
    "intermediate": ((MOTOR_INERTIA + I1) / R1**2 + I2, I3 + (I4 + LOAD_INERTIA) * R2**2),
    "output": ((MOTOR_INERTIA + I1) / (R1 * R2)**2 + (I2 + I3) / R2**2 + I4, LOAD_INERTIA),
}
DAMPING = {name: _shaft_damping(COUPLING_DAMPING if name == "coupling" else SHAFT_DAMPING, SHAFTS[name], *SIDES[name])
           for name in SHAFTS}


RATIO = 61 / 23 * 47 / 19  # the gearbox's: the load torque balances the motor's through the tooth counts
model.set_physical(
    I_m=f"{MOTOR_INERTIA} kg*m^2", I_L=f"{LOAD_INERTIA} kg*m^2",
    k_c=f"{SHAFTS['coupling']:g} N*m/rad", k_i=f"{SHAFTS['intermediate']:g} N*m/rad",
    k_o=f"{SHAFTS['output']:g} N*m/rad",
    c_c=f"{DAMPING['coupling']:.6g} N*m*s/rad", c_i=f"{DAMPING['intermediate']:.6g} N*m*s/rad",
    c_o=f"{DAMPING['output']:.6g} N*m*s/rad",
    cZ1=f"{_mesh_damping(stage1, gear1, gear2):.6g} N*s/m", cZ2=f"{_mesh_damping(stage2, gear3, gear4):.6g} N*s/m",
    eta1="80 um", eta2="120 um",
    M_m=f"{TORQUE} N*m", M_L=f"{TORQUE * RATIO!r} N*m", speed=SPEED,
)
# the train at rest under the mean torques (each coupling carries its torque: its twist or deflection is that over
# its stiffness), so that a run starts on the operating point: shafts twist backwards (psi_b - psi_a < 0), meshes
# deflect forwards
T_INPUT, T_MIDDLE = TORQUE, TORQUE * 61 / 23
model.set_initial_state(
    x1=f"{-T_INPUT / SHAFTS['coupling']!r} rad",
    x2=f"{T_INPUT / gear1.geometry.base_radius / model.physical['kZ1'].si!r} m",
    x3=f"{-T_MIDDLE / SHAFTS['intermediate']!r} rad",
    x4=f"{T_MIDDLE / gear3.geometry.base_radius / model.physical['kZ2'].si!r} m",
    x5=f"{-TORQUE * RATIO / SHAFTS['output']!r} rad",
)
model.describe(
    speed="speed of the motor",
    I_m="rotor inertia of the motor (assumed)",
    I_L="inertia of the driven machine (assumed)",
    k_c="torsional stiffness of the flexible coupling",
    k_i="torsional stiffness of the intermediate shaft",
    k_o="torsional stiffness of the output shaft",
    c_c="damping of the coupling (an elastomer: 0.05 of critical in its own mode, the rest of the train rigid)",
    c_i="damping of the intermediate shaft (0.02 of critical in its own mode)",
    c_o="damping of the output shaft (0.02 of critical in its own mode)",
    kZ1="mean stiffness of the first mesh, from its geometry (potential-energy method)",
    kZ2="mean stiffness of the second mesh, from its geometry",
    cZ1="damping of the first mesh (damping ratio 0.05)",
    cZ2="damping of the second mesh (damping ratio 0.05)",
    eta1="backlash of the first stage along its line of action",
    eta2="backlash of the second stage along its line of action",
    M_m="motor torque",
    M_L="load torque (the motor's times the gearbox ratio 61/23 x 47/19)",
)
