"""Drivetrain components, joined at their flanges (bodies) like Modelica Rotational.

Bodies carry a rotation angle psi (the angle left after the steady rotation is
removed); a body declared ``fixed=True`` (a held ring gear, a grounded carrier) has
none. Couplings join two bodies: a :class:`Mesh` along the line of action,
a :class:`Shaft` in torsion. :class:`Torque` acts on one body. A :class:`Planet`
is a gear whose axis is carried by another body (its carrier), at an angular
position on it: the planetary gear sets of Lin & Parker's rotational model.

Sign conventions (those of the paper's Eqs. 1 and 8, extended to planetary sets):

* the two gears of a mesh are counted in opposite senses. An external pair turns in
  opposite senses, so its deflection is ``delta = r_a*psi_a - r_b*psi_b`` (rigid
  rolling is delta = 0); a ring gear (``internal=True``) and its pinion turn the same
  way, so ``delta = r_a*psi_a + r_b*psi_b``;
* on a carrier the angles are those relative to the carrier: the sun, ring and
  carrier (the central members) are counted in one sense and each planet in the
  opposite one, so a sun-planet mesh deflects by
  ``r_s (psi_s - psi_c) - r_p (psi_p + psi_c)`` and a ring-planet mesh by
  ``r_r (psi_r - psi_c) + r_p (psi_p + psi_c)`` (Lin & Parker's
  ``u_s + u_p - u_c cos(alpha)`` and ``u_r - u_p - u_c cos(alpha)`` with
  ``u = r theta`` in one sense, ``theta_p = -psi_p`` and ``r_c cos(alpha) = r_s + r_p``
  resp. ``r_r - r_p``);
* shaft twist ``theta = psi_b - psi_a``;
* a torque with ``load=True`` is a resisting torque M: it enters as -M (the
  paper's M2 and M3); otherwise it drives (+M, the paper's M1).

Every quantity is a number, a parameter name or a SymPy formula (see
:mod:`gearsym.model.expressions`). Components are frozen: a change after
declaring means declaring again, so nothing derived from them goes stale.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional, Union

from ..geometry import GearGeometry, StiffnessOptions
from ..units import Measure
from .expressions import ExprLike
from .shaft_orders import teeth_of
from .geometric import GEOMETRY_HARMONICS, ComputedStiffness, body_values, computed_stiffness, geometry_from
from .stiffness import rectangular_mesh_stiffness


@dataclass(eq=False, frozen=True)
class Body:
    """A rotating inertia (base class of :class:`Gear` and :class:`Disk`).

    ``fixed=True`` grounds it (a held ring gear or carrier): it has no angle and needs no inertia.
    ``mass``: the body's mass, which a body on a :class:`Bearing` needs (its centre translates).
    """

    name: str
    inertia: Optional[ExprLike] = None
    fixed: bool = field(default=False, kw_only=True)
    mass: Optional[ExprLike] = field(default=None, kw_only=True)

    @property
    def radius(self) -> Optional[ExprLike]:
        return None

    @property
    def tooth_count(self) -> Optional[int]:
        return getattr(self, "teeth", None)

    @property
    def speed_parameter(self) -> Optional[str]:
        """The name of the parameter giving this body's rotational speed, if it is the declared operating speed."""
        return getattr(self, "speed", None)

    def physical_values(self) -> dict[str, Measure]:
        """The physical values this body gives the model when it is added (a gear from its geometry: its
        inertia and base radius); none for a body declared with parameters."""
        geometry = getattr(self, "geometry", None)
        if geometry is None:
            return {}
        mass = str(self.mass) if isinstance(self.mass, str) and self.mass.isidentifier() else None
        return body_values(geometry, str(self.inertia), str(self.radius), mass)


@dataclass(eq=False, frozen=True)
class Gear(Body):
    """A gear wheel: moment of inertia and base-circle radius.

    For physical values (:meth:`Drivetrain.set_physical`): ``teeth``, its tooth count (a mesh's frequency
    is teeth x shaft speed), and ``speed``, the name of the parameter that gives this gear's rotational
    speed, on the one body whose speed is the operating point (``speed="speed"``; then
    ``--set speed="3000 rpm"``). ``internal=True`` makes it a ring gear (internal teeth).
    ``geometry``: the :class:`~gearsym.geometry.GearGeometry` of a gear declared from it (:meth:`from_geometry`).
    """

    base_radius: ExprLike = "r"
    teeth: Optional[int] = None
    speed: Optional[str] = None
    internal: bool = field(default=False, kw_only=True)
    geometry: Optional[GearGeometry] = field(default=None, kw_only=True)

    def __post_init__(self):
        if self.teeth is not None:  # (a count that is no count is wrong whether or not a fault needs it yet)
            teeth_of(self.teeth, f"Gear {self.name!r}")

    @classmethod
    def from_geometry(cls, name: str, geometry: Optional[GearGeometry] = None, *, inertia: Optional[str] = None,
                      base_radius: Optional[str] = None, speed: Optional[str] = None, mass: Optional[str] = None,
                      **dimensions) -> "Gear":
        """A gear declared from its geometry: a :class:`~gearsym.geometry.GearGeometry` (SI), or its dimensions
        as quantities with units (``teeth=28, module="3.175 mm", pressure_angle="20 deg", face_width="6.35 mm"``,
        and ``profile_shift``, ``helix_angle``, ``bore_diameter``, the rack's coefficients, ``material``).

        Its inertia is the disk with its bore (:attr:`GearGeometry.polar_inertia`), its base radius and tooth count
        the geometry's: the parameters ``inertia`` and ``base_radius`` (default ``I_<name>``, ``r_<name>``) get them
        as physical values when the gear is added to a drivetrain, and ``mass`` (a parameter name, for a gear on a
        :class:`Bearing`) the body's mass. A :meth:`Mesh.from_gears` between two such gears computes its stiffness
        from them.
        """
        geometry = geometry_from(f"Gear {name!r}", geometry, dimensions)
        return cls(name, inertia=inertia or f"I_{name}", base_radius=base_radius or f"r_{name}",
                   teeth=geometry.teeth, speed=speed, geometry=geometry, mass=mass)

    @property
    def radius(self) -> ExprLike:
        return self.base_radius


@dataclass(eq=False, frozen=True)
class Planet(Gear):
    """A planet gear: its axis turns with ``carrier`` (any body, often a :class:`Disk`), at the angle
    ``position`` (radians, in the carrier's positive sense) from the planet whose meshes have phase 0.

    Its angle is counted opposite to the carrier's (see the module's conventions). The carrier's inertia
    is that of the rotational model: the carrier's own plus each planet's mass times the carrier radius
    squared. With tooth counts on the central gears, each mesh's stiffness phase follows from
    ``position`` (Parker & Lin 2004: ``-Z position`` in the mesh phase, with the sign of the central gear's
    rotation relative to the carrier), and a sun and a ring with teeth must let the planet be assembled
    there (``(Z_sun + Z_ring) position / 2 pi`` a whole number).

    A planet on a :class:`Bearing` (its pin) translates in the carrier's frame, radially and tangentially;
    ``orbit`` is then the radius of the circle its centre turns on (Lin & Parker's carrier radius r_c).
    """

    carrier: Optional[BodyRef] = field(default=None, kw_only=True)
    position: ExprLike = field(default=0, kw_only=True)
    orbit: Optional[ExprLike] = field(default=None, kw_only=True)


@dataclass(eq=False, frozen=True)
class Disk(Body):
    """A disk (flywheel, rotor, load inertia): moment of inertia only (``speed`` as for :class:`Gear`)."""

    speed: Optional[str] = None


BodyRef = Union[Body, str]


@dataclass(eq=False, frozen=True)
class Mesh:
    """A gear mesh between two gears, acting along the line of action.

    Elastic force ``stiffness * variation(phi) * g(delta, backlash)``, damping force
    ``damping * d(delta)/dt``; ``phi = order * omega * t + phase`` is the mesh phase.

    * ``variation``: dimensionless, 2*pi-periodic in ``phi`` (default: the documented
      smoothed rectangular wave, :func:`rectangular_mesh_stiffness`).
    * ``order``: the mesh frequency over the forcing frequency (the first mesh's). Leave it out: with the
      tooth counts of the gears it is derived from them (``19/61`` for the 19/47 stage behind a 23/61 one,
      :mod:`.mesh_orders`), without them it is 1; one given that the teeth contradict is refused.
    * ``coordinate``: name of the relative coordinate (the mesh deflection).
    * ``function``: name under which the nondimensional stiffness k(tau) appears (default ``k`` for the first
      mesh, ``k_<coordinate>`` for the others).
    * ``damping_group``, ``stiffness_group``: names of the damping ratio group (the paper's zeta) and, for a
      mesh after the first, of its mean stiffness relative to the first's (default ``zeta_<coordinate>``,
      ``K_<coordinate>``).
    * ``backlash``: the clearance eta; 0 gives a linear mesh.
    * ``phase``: added to the mesh phase; a planet's position adds its own (see :class:`Planet`).
    * ``computed``: the stiffness of a mesh declared from its gears' geometry (:meth:`from_gears`).
    * ``pressure_angle``, ``centres``: where the mesh's line of action lies, for gears that translate (on a
      :class:`Bearing`): the pressure angle and the direction of the line of centres from gear a's centre to
      gear b's (radians from the x axis; derived from the planet's position for a planet's mesh). The
      deflection is then the projection of both centres' motions and both rotations on the line of action of
      the flank that gear a's positive rotation closes (see :mod:`gearsym.model.geometry_rows`).
    """

    name: str
    gear_a: BodyRef
    gear_b: BodyRef
    stiffness: ExprLike = "kZ"
    damping: ExprLike = "cZ"
    backlash: ExprLike = "eta"
    variation: ExprLike = field(default_factory=rectangular_mesh_stiffness)
    order: Optional[ExprLike] = None
    phase: ExprLike = 0
    coordinate: Optional[str] = None
    function: Optional[str] = None
    damping_group: Optional[str] = None
    stiffness_group: Optional[str] = None
    computed: Optional[ComputedStiffness] = field(default=None, kw_only=True, repr=False)
    pressure_angle: ExprLike = field(default=0, kw_only=True)
    centres: Optional[ExprLike] = field(default=None, kw_only=True)

    @property
    def ends(self) -> tuple[BodyRef, BodyRef]:
        return (self.gear_a, self.gear_b)

    @classmethod
    def from_gears(cls, name: str, gear_a: Gear, gear_b: Gear, *, harmonics: int = GEOMETRY_HARMONICS,
                   smoothed: bool = True, options: Optional[StiffnessOptions] = None, centre_distance=None,
                   stiffness: str = "kZ", **mesh) -> "Mesh":
        """A mesh between two gears declared from their geometry (``gear_a`` drives): its stiffness over one mesh
        period by the potential-energy method (:func:`gearsym.geometry.mesh_stiffness`, ``options``), entered as its
        mean (the physical value of ``stiffness``, N/m, given when the mesh is added to a drivetrain) times its
        Fourier series in the mesh phase to ``harmonics`` terms (with Lanczos's sigma factors unless
        ``smoothed=False``). The mesh frequency is the gears' tooth counts times their speed, and the phase
        0 is the instant a pair of teeth comes into contact. ``centre_distance`` (with its unit) opens a backlash
        in the geometry, None meshes tight; the model's backlash is still the ``backlash`` parameter. The other
        keywords are :class:`Mesh`'s (``damping``, ``backlash``, ``coordinate`` ...).
        """
        computed = computed_stiffness(f"Mesh {name!r}", getattr(gear_a, "geometry", None),
                                      getattr(gear_b, "geometry", None),
                                      (getattr(gear_a, "name", gear_a), getattr(gear_b, "name", gear_b)), options,
                                      centre_distance, harmonics, smoothed)
        return cls(name, gear_a, gear_b, stiffness=stiffness, variation=computed.variation(), computed=computed, **mesh)

    def physical_values(self) -> dict[str, Measure]:
        """The physical values this mesh gives the model when it is added: the mean of a computed stiffness."""
        return {} if self.computed is None else self.computed.values(str(self.stiffness))


@dataclass(eq=False, frozen=True)
class Shaft:
    """A torsional shaft from body ``a`` to body ``b`` (twist ``psi_b - psi_a``).

    Its relative coordinate is the twist scaled to a length,
    ``x = radius * (psi_b - psi_a)`` as the paper's ``x2 = r2 (psi3 - psi2)``;
    ``radius`` defaults to the base radius of ``a`` (or of ``b`` if ``a`` is a disk).
    A constant torque that loads the twist (a motor driving through the shaft)
    stays in the equations as forcing, with the static twist it causes. ``forced=False``
    is an assumption to declare (the paper's, for its flexible shaft): the reduction
    then requires that no constant torque loads the twist and drops it, which is the
    torque-balance condition of Eq. 10.
    """

    name: str
    a: BodyRef
    b: BodyRef
    stiffness: ExprLike = "kS"
    damping: ExprLike = 0
    coordinate: Optional[str] = None
    radius: Optional[ExprLike] = None
    forced: bool = True

    @property
    def ends(self) -> tuple[BodyRef, BodyRef]:
        return (self.a, self.b)


@dataclass(eq=False, frozen=True)
class Harmonic:
    """One harmonic ``amplitude * cos(order * omega * t + phase)`` of a torque.

    ``group`` names the nondimensional forcing group it ends up in (the paper's
    B1 for the excitation, D for the weak resonant term); harmonics of the same
    order and phase on different bodies add up into one group.
    """

    amplitude: ExprLike
    phase: ExprLike = 0
    order: int = 1
    group: Optional[str] = None


@dataclass(eq=False, frozen=True)
class Torque:
    """An external torque ``mean + sum(harmonics)`` on one body (see ``load`` above)."""

    name: str
    on: BodyRef
    mean: ExprLike = 0
    harmonics: tuple[Harmonic, ...] = ()
    load: bool = False


@dataclass(eq=False, frozen=True)
class Bearing:
    """The bearing of a body's centre: translational stiffness and damping, and a torsional support.

    The body ``on`` gets its centre's translations (it must declare a ``mass``): ``directions`` "xy" (both),
    "x" or "y" (the other held rigidly), in the fixed frame, or in the carrier's frame for the members of a
    planetary set whose planets translate (Lin & Parker: x, y of the sun, ring and carrier turn with the
    carrier). On a :class:`Planet` it is the planet's pin on its carrier: x is radial, y tangential, and
    the deflection is the planet's centre relative to the pin (the carrier's translation and rotation
    carried to it). ``stiffness`` (N/m) and ``damping`` act in both directions unless ``stiffness_y`` and
    ``damping_y`` give the y direction its own (isotropic bearings only in a rotating frame).
    ``torsional``: the stiffness (N m/rad) of a torsional support holding the body's rotation (Lin & Parker's
    k_u, which acts on u = r theta, is k_u r^2 here), with ``torsional_damping``; None: the body turns freely.
    A torsional support's coordinate is the support's twist times the body's base radius (a length).
    """

    name: str
    on: BodyRef
    stiffness: ExprLike = "k_b"
    damping: ExprLike = 0
    stiffness_y: Optional[ExprLike] = None
    damping_y: Optional[ExprLike] = None
    directions: str = "xy"
    torsional: Optional[ExprLike] = None
    torsional_damping: ExprLike = 0
    coordinates: Optional[tuple[str, ...]] = field(default=None, kw_only=True)

    @property
    def ends(self) -> tuple[BodyRef]:
        return (self.on,)


Coupling = Union[Mesh, Shaft]
Component = Union[Body, Mesh, Shaft, Torque, Bearing]
