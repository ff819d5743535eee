"""Lin & Parker's translational-rotational planetary gear set: sun, ring and carrier translate on their bearings
and turn, each planet translates radially and tangentially on its pin in the carrier's frame and turns: 3(N + 3)
degrees of freedom (J. Lin and R. G. Parker, Analytical characterization of the unique properties of planetary
gear free vibration, J. Vib. Acoust. 121 (1999) 316-321). N = 3 planets, equally spaced (``--set planets=4``).

Every mesh's deflection is the projection of both centres' motions and both rotations on its line of action
(sun-planet: Lin & Parker's y_s cos psi_sn - x_s sin psi_sn - xi_n sin alpha_s - eta_n cos alpha_s + u_s + u_n),
each mesh with periodic stiffness, damping and backlash, its stiffness phase from the tooth counts and the planet's
position (Parker & Lin 2004). The translations are written in the carrier's frame, which turns at the carrier's
speed: its Coriolis and centripetal terms are kept (Lin & Parker's G and K_Omega), with the carrier's speed from the
forcing frequency and the teeth; ``--set stationary=1`` leaves them out (Lin & Parker's stationary model, the one
their modal properties are stated for; the natural modes are the stationary model's either way).

Sources of the defaults. Lin & Parker 1999, Table 1 (the example system; values as we read them, not checked
against the paper in this revision): masses m_s 0.4, m_r 2.35, m_c 5.43, m_p 0.66 kg; I/r^2 of sun, ring, carrier,
planet 0.39, 3.00, 6.29, 0.61 kg (the inertias below are I/r^2 times the radius squared); mesh stiffness k_sp =
k_rp = 5e8 N/m; bearing stiffness k_p = k_s = k_r = k_c = 1e8 N/m; the ring's torsional support k_ru = 1e9 N/m on
u = r theta, 1e9 r_r^2 N m/rad here; sun and carrier free to turn (k_su = k_cu = 0: not declared; give one with
--set k_su="... N*m/rad" to hold the sun); pressure angles 24.6 deg; the sun's base radius 38.7 mm.
Assumptions (ours): the tooth counts 26/34/94 (so that N = 3, 4, 5 can be spaced equally), and from them the planet's
and the ring's base radii (r_s 34/26, r_s 94/26) and the carrier radius (r_s + r_p)/cos alpha_s; the natural
frequencies do not depend on the radii (the masses I/r^2 are the paper's). The operating point: the sun at
3000 rpm with 200 N m, the carrier loaded in balance, mesh damping 5 % of critical on the sun-planet mesh's
effective mass, bearings undamped as in the paper, a backlash of 50 um, a stiffness variation of 20 %.
"""
import math

import sympy as sp

from gearsym import Bearing, Disk, Drivetrain, Gear, Harmonic, Mesh, Planet, Torque

#: its C is committed (generated/: 0.9 MB, its tangent matrix by column, gearsym/codegen/columns.py), its derivation
#: page not (``gearsym docs --all`` leaves it out: a megabyte of formulas)
PREGENERATED = "code"
OPTIONS = {"planets": 3, "stationary": 0, "k_su": 0, "k_cu": 0}  # model options: --set planets=4, stationary=1
SUN_TEETH, PLANET_TEETH, RING_TEETH = 26, 34, 94
ALPHA = 24.6  # deg, both meshes
R_SUN = 38.7e-3  # m, base radius
MASSES = dict(m_s=0.4, m_r=2.35, m_c=5.43, m_p=0.66)  # kg
I_OVER_R2 = dict(s=0.39, r=3.00, c=6.29, p=0.61)  # kg
MESH_STIFFNESS, BEARING_STIFFNESS, RING_SUPPORT = 5e8, 1e8, 1e9  # N/m (the support on u = r theta)
SUN_TORQUE, SUN_SPEED = 200.0, "3000 rpm"
DAMPING_RATIO = 0.05


def radii() -> dict[str, float]:
    """Base radii from the sun's and the teeth, the carrier radius from the pressure angle (m)."""
    r_s = R_SUN
    r_p, r_r = r_s * PLANET_TEETH / SUN_TEETH, r_s * RING_TEETH / SUN_TEETH
    return dict(r_s=r_s, r_p=r_p, r_r=r_r, r_c=(r_s + r_p) / math.cos(math.radians(ALPHA)))


def build(planets: int = 3, stationary: int = 0, k_su: int = 0, k_cu: int = 0) -> Drivetrain:
    """The set with ``planets`` equally spaced planets; ``stationary=1`` without the frame's Coriolis and
    centripetal terms; ``k_su``, ``k_cu`` nonzero (N m/rad) hold the sun or the carrier torsionally."""
    if not 3 <= planets <= 8 or (SUN_TEETH + RING_TEETH) % planets:
        raise ValueError(f"planets must be 3, 4, 5, 6 or 8 (equally spaced: (Z_sun + Z_ring)/N whole), got {planets}")
    if stationary not in (0, 1):
        raise ValueError(f"stationary is 0 (the frame's terms kept) or 1 (Lin & Parker's stationary model), "
                         f"got {stationary}")
    m = Drivetrain("planetary_translational",
                   title=f"Lin & Parker's translational planetary gear set, {planets} planets"
                         + (" (stationary model)" if stationary else ""))
    sun = m.add(Gear("sun", inertia="I_s", base_radius="r_s", teeth=SUN_TEETH, mass="m_s", speed="speed"))
    ring = m.add(Gear("ring", inertia="I_r", base_radius="r_r", teeth=RING_TEETH, internal=True, mass="m_r"))
    carrier = m.add(Disk("carrier", inertia="I_c", mass="m_c"))
    gears = [m.add(Planet(f"planet{n + 1}", inertia="I_p", base_radius="r_p", teeth=PLANET_TEETH, mass="m_p",
                          carrier=carrier, position=2 * sp.pi * n / planets, orbit="r_c"))
             for n in range(planets)]
    for n, planet in enumerate(gears):
        m.add(Mesh(f"sun_planet{n + 1}", sun, planet, stiffness="k_sp", damping="c_sp", pressure_angle="alpha_s",
                   coordinate=f"x{n + 1}", damping_group="zeta"))
    for n, planet in enumerate(gears):
        m.add(Mesh(f"ring_planet{n + 1}", ring, planet, stiffness="k_rp", damping="c_rp", pressure_angle="alpha_r",
                   coordinate=f"y{n + 1}", damping_group="zeta_r", stiffness_group="K_r"))
    m.add(Bearing("sun_bearing", sun, stiffness="k_s", torsional="k_su" if k_su else None))
    m.add(Bearing("ring_bearing", ring, stiffness="k_r", torsional="k_ru"))
    m.add(Bearing("carrier_bearing", carrier, stiffness="k_c", torsional="k_cu" if k_cu else None))
    for planet in gears:
        m.add(Bearing(f"{planet.name}_pin", planet, stiffness="k_p"))
    m.add(Torque("M_s", on=sun, mean="M_s", harmonics=(Harmonic("M_a", phase="Theta", group="B1"),)))
    m.add(Torque("M_c", on=carrier, mean="M_c", load=True))
    if stationary:
        m.set_frame_terms(False)
    r = radii()
    inertias = {f"I_{k}": v * r[f"r_{k}"] ** 2 for k, v in I_OVER_R2.items()}
    along = 1 / I_OVER_R2["s"] + 1 / I_OVER_R2["p"]  # the sun-planet mesh's 1/effective mass, torsionally
    damping = 2 * DAMPING_RATIO * math.sqrt(MESH_STIFFNESS / along)
    m.set_physical(
        **{k: f"{v} kg" for k, v in MASSES.items()},
        **{k: f"{v:.9g} kg*m^2" for k, v in inertias.items()},
        **{k: f"{v * 1e3:.9g} mm" for k, v in r.items()},
        alpha_s=f"{ALPHA} deg", alpha_r=f"{ALPHA} deg",
        k_sp=f"{MESH_STIFFNESS:g} N/m", k_rp=f"{MESH_STIFFNESS:g} N/m",
        c_sp=f"{damping:.9g} N*s/m", c_rp=f"{damping:.9g} N*s/m",
        k_p=f"{BEARING_STIFFNESS:g} N/m", k_s=f"{BEARING_STIFFNESS:g} N/m", k_r=f"{BEARING_STIFFNESS:g} N/m",
        k_c=f"{BEARING_STIFFNESS:g} N/m", k_ru=f"{RING_SUPPORT * r['r_r'] ** 2:.9g} N*m/rad",
        eta="50 um", speed=SUN_SPEED, Theta=0,
        M_s=f"{SUN_TORQUE} N*m", M_a=f"{0.1 * SUN_TORQUE:.9g} N*m",
        M_c=f"{SUN_TORQUE * (SUN_TEETH + RING_TEETH) / SUN_TEETH:.9g} N*m",
    )
    if k_su:
        m.set_physical(k_su=f"{k_su} N*m/rad")
    if k_cu:
        m.set_physical(k_cu=f"{k_cu} N*m/rad")
    m.set_defaults(k_a=0.2)
    m.describe(
        speed="speed of the sun (the input; the ring is held by its support, the carrier is the output)",
        alpha_s="pressure angle of the sun-planet meshes", alpha_r="pressure angle of the ring-planet meshes",
        r_c="carrier radius (where the planets' centres turn)",
        k_sp="mean sun-planet mesh stiffness", k_rp="mean ring-planet mesh stiffness",
        k_p="planet bearing stiffness (radial and tangential, on the carrier's pin)",
        k_s="sun bearing stiffness", k_r="ring bearing stiffness", k_c="carrier bearing stiffness",
        k_ru="the ring's torsional support (Lin & Parker's k_ru = 1e9 N/m on u = r theta, times r_r^2)",
        eta="backlash of every mesh", k_a="relative amplitude of the mesh stiffness variation",
        M_a="torque fluctuation on the sun at the mesh frequency (10 % of the mean)",
    )
    return m


model = build()
