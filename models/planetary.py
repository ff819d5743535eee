"""Planetary gear set: sun input, ring held, carrier output, N equally spaced planets (default 3).

Lin & Parker's rotational model (J. Vib. Acoust. 121, 1999): the sun, the carrier and N identical
planets turn; the ring gear is declared fixed. Each planet meshes with the sun and with the ring, every
mesh with periodic stiffness, damping and backlash, so the 2N meshes close N - 1 kinematic loops and the
reduction keeps N + 1 independent deflections (a spanning set of the meshes, in declaration order: each
planet's sun mesh, then the first planet's ring mesh); the other ring meshes are combinations of those.
Teeth 26/34/94: (Z_sun + Z_ring)/N is whole for N = 3, 4, 5 (and 6, 8), so the planets can be assembled
equally spaced, and each mesh's stiffness phase follows from its planet's position (Parker & Lin 2004);
Z_sun/N is not whole, so the planets' meshes are out of phase (sequentially phased).
The carrier inertia is the rotational model's: its own plus each planet's mass at the carrier radius.
Nondimensional values (illustrative): radii proportional to the teeth, inertias as solid disks.
"""
import sympy as sp

from gearsym import Disk, Drivetrain, Gear, Harmonic, Mesh, Planet, Torque

SUN_TEETH, PLANET_TEETH, RING_TEETH = 26, 34, 94
RADII = dict(r_s=SUN_TEETH / 20, r_p=PLANET_TEETH / 20, r_r=RING_TEETH / 20)  # in proportion to the teeth
INERTIAS = dict(I_s=RADII["r_s"] ** 4, I_p=RADII["r_p"] ** 4)  # solid disks of one width: ~ r^4
RING_INERTIA = RADII["r_r"] ** 4 - (RADII["r_r"] - 0.5) ** 4  # a rim of that width
if not RADII["r_s"] + 2 * RADII["r_p"] == RADII["r_r"]:
    raise ValueError("the planets must fit between the sun and the ring")


def carrier_inertia(planets: int) -> float:
    """The carrier's own inertia (that of one planet's disk at its radius) plus each planet's mass, ~ r_p^2,
    at the carrier radius r_s + r_p."""
    return (RADII["r_s"] + RADII["r_p"]) ** 4 / 4 + planets * RADII["r_p"] ** 2 * (RADII["r_s"] + RADII["r_p"]) ** 2


def ring_mesh_share(planets: int) -> float:
    """K_r for a ring mesh as stiff as a sun mesh: its r^2/I along its line over the sun mesh's."""
    r_s, r_p, r_c, r_r = RADII["r_s"], RADII["r_p"], RADII["r_s"] + RADII["r_p"], RADII["r_r"]
    i_s, i_p, i_c = INERTIAS["I_s"], INERTIAS["I_p"], carrier_inertia(planets)
    return (r_p**2 / i_p + (r_r - r_p) ** 2 / i_c) / (r_s**2 / i_s + r_p**2 / i_p + r_c**2 / i_c)


def balanced_forcing(planets: int, ring_fixed: bool) -> dict:
    """B0 (and B0_y1) of torques in balance (no rigid-body acceleration) that load each mesh with the force that
    deflects it by the length unit, and a torque fluctuation of a fifth of the mean at the mesh frequency (B1).
    Each planet balances equal sun and ring mesh forces F: M_s = N r_s F, M_r = N r_r F, M_c = M_s + M_r."""
    r_s, r_p, r_c, r_r = RADII["r_s"], RADII["r_p"], RADII["r_s"] + RADII["r_p"], RADII["r_r"]
    i_s, i_p, i_c = INERTIAS["I_s"], INERTIAS["I_p"], carrier_inertia(planets)
    stiffness = 1 / (r_s**2 / i_s + r_p**2 / i_p + r_c**2 / i_c)  # kZ by the time-unit condition
    m_s, m_r = planets * r_s * stiffness, planets * r_r * stiffness
    m_c = m_s + m_r
    forcing = dict(B0=m_s * r_s / i_s + m_c * r_c / i_c, B0_y1=m_c * (r_r - r_p) / i_c, B1=0.2 * m_s * r_s / i_s)
    if not ring_fixed:
        forcing["B0_y1"] += m_r * r_r / RING_INERTIA
    return forcing


def build(planets: int = 3, name: str = "planetary", ring_fixed: bool = True, title: str | None = None,
          carrier_load: bool = True) -> Drivetrain:
    """The planetary set with ``planets`` equally spaced planets; ``ring_fixed=False`` frees the ring (a
    differential: sun and ring driven, carrier loaded); ``carrier_load=False`` leaves the carrier's load
    torque (and the forcing defaults) to a stage that it drives."""
    title = title or (f"Planetary gear set, {planets} planets, ring held (sun in, carrier out)" if ring_fixed
                      else f"Planetary differential, {planets} planets (sun and ring in, carrier out)")
    m = Drivetrain(name, title=title)
    sun = m.add(Gear("sun", inertia="I_s", base_radius="r_s", teeth=SUN_TEETH))
    ring = m.add(Gear("ring", inertia=None if ring_fixed else "I_r", base_radius="r_r", teeth=RING_TEETH,
                      internal=True, fixed=ring_fixed))
    carrier = m.add(Disk("carrier", inertia="I_c"))
    gears = [m.add(Planet(f"planet{n + 1}", inertia="I_p", base_radius="r_p", teeth=PLANET_TEETH,
                          carrier=carrier, position=2 * sp.pi * n / planets)) for n in range(planets)]
    for n, planet in enumerate(gears):
        m.add(Mesh(f"sun_planet{n + 1}", sun, planet, coordinate=f"x{n + 1}", damping_group="zeta"))
    for n, planet in enumerate(gears):
        m.add(Mesh(f"ring_planet{n + 1}", ring, planet, coordinate=f"y{n + 1}", stiffness="kZ_r", damping="cZ_r", damping_group="zeta_r",
                   stiffness_group="K_r", function="k_r" if n == 0 else None))
    m.add(Torque("M_s", on=sun, mean="M_s", harmonics=(Harmonic("M_a", phase="Theta", group="B1"),)))
    if not ring_fixed:
        m.add(Torque("M_r", on=ring, mean="M_r"))
    if carrier_load:
        m.add(Torque("M_c", on=carrier, mean="M_c", load=True))
    ring_share = ring_mesh_share(planets)
    m.set_defaults(omega=1.0, zeta=0.05, zeta_r=0.05 * ring_share**0.5, K_r=ring_share, Theta=0.0, eta=1.0, k_a=0.2,
                   **INERTIAS, **RADII, I_c=carrier_inertia(planets))
    if carrier_load:
        m.set_defaults(**balanced_forcing(planets, ring_fixed))
    if not ring_fixed:
        m.set_defaults(I_r=RING_INERTIA)
    m.describe(
        omega="forcing frequency (= mesh frequency) in units of omega_n, the sun-planet mesh's",
        eta="backlash of every mesh in the length unit",
        K_r="mean stiffness of a ring-planet mesh relative to a sun-planet mesh (default: equally stiff meshes)",
        zeta_r="damping group of a ring-planet mesh (default: the sun meshes' damping ratio)",
        k_a="relative amplitude of the mesh stiffness variation",
        I_c="carrier inertia with the planets' masses at the carrier radius r_s + r_p",
    )
    return m


model = build()
