"""Bad declarations raise gearsym.ModelError naming the component to fix."""
from __future__ import annotations

import pytest
import sympy as sp

import gearsym
from conftest import fresh_one_stage
from gearsym import Disk, Drivetrain, FirstOrderSystem, Gear, Harmonic, Mesh, ModelError, Shaft, Torque


def pair(name="bad", I1="I1", r1="r1"):
    m = Drivetrain(name)
    a = m.add(Gear("gear1", inertia=I1, base_radius=r1))
    b = m.add(Gear("gear2", inertia="I2", base_radius="r2"))
    return m, a, b


def test_unconnected_inertia():
    m, a, b = pair()
    m.add(Mesh("mesh", a, b))
    m.add(Disk("flywheel", inertia="I3"))
    with pytest.raises(ModelError, match=r"Disk 'flywheel'.*not connected") as err:
        m.form_eoms()
    assert "flywheel" in err.value.component


@pytest.mark.parametrize("inertia", [-1, 0, "-2", -0.5])
def test_non_positive_inertia_number(inertia):
    m, a, b = pair(I1=inertia)
    m.add(Mesh("mesh", a, b))
    with pytest.raises(ModelError, match=r"Gear 'gear1'.*moment of inertia must be positive"):
        m.form_eoms()


def test_non_positive_inertia_via_default():
    m, a, b = pair()
    m.add(Mesh("mesh", a, b))
    m.set_defaults(I1=0)
    with pytest.raises(ModelError, match=r"Gear 'gear1'.*moment of inertia must be positive.*I1 = 0"):
        m.form_eoms()


def test_non_positive_inertia_via_default_of_shipped_builder():
    m = fresh_one_stage("neg_inertia")
    m.set_defaults(I2=-3.0)
    with pytest.raises(ModelError, match=r"Gear 'gear2'.*moment of inertia must be positive"):
        gearsym.reduce(m)


@pytest.mark.parametrize("radius", [0, -2, "-r0*r0 - 1"])
def test_non_positive_radius(radius):
    m, a, b = pair(r1=radius)
    m.add(Mesh("mesh", a, b))
    if radius == "-r0*r0 - 1":
        m.set_defaults(r0=1.0)
    with pytest.raises(ModelError, match=r"Gear 'gear1'.*base radius must be positive"):
        m.form_eoms()


def test_non_positive_radius_via_default():
    m, a, b = pair()
    m.add(Mesh("mesh", a, b))
    m.set_defaults(r2=-1.0)
    with pytest.raises(ModelError, match=r"Gear 'gear2'.*base radius must be positive"):
        m.form_eoms()


def test_mesh_gear_to_itself():
    m, a, b = pair()
    m.add(Mesh("selfmesh", a, a))
    with pytest.raises(ModelError, match=r"Mesh 'selfmesh'.*'gear1' to itself"):
        m.form_eoms()


def test_shaft_body_to_itself():
    m, a, b = pair()
    m.add(Mesh("mesh", a, b))
    m.add(Shaft("selfshaft", "gear2", "gear2"))
    with pytest.raises(ModelError, match=r"Shaft 'selfshaft'.*'gear2' to itself"):
        m.form_eoms()


def test_mesh_to_undeclared_body_suggests():
    m, a, b = pair()
    m.add(Mesh("mesh", a, "gaer2"))
    with pytest.raises(ModelError, match=r"Mesh 'mesh'.*'gaer2'.*Did you mean 'gear2'"):
        m.form_eoms()


def test_torque_on_undeclared_body():
    m, a, b = pair()
    m.add(Mesh("mesh", a, b))
    m.add(Torque("drive", on="gear_1", mean="M1"))
    with pytest.raises(ModelError, match=r"Torque 'drive'.*'gear_1'.*Did you mean 'gear1'"):
        m.form_eoms()


def test_mesh_with_disk():
    m, a, b = pair()
    d = m.add(Disk("rotor", inertia="I3"))
    m.add(Mesh("mesh", a, b))
    m.add(Mesh("diskmesh", b, d))
    with pytest.raises(ModelError, match=r"Mesh 'diskmesh'.*'rotor'.*Disk without a base radius"):
        m.form_eoms()


def test_misspelt_default():
    m = fresh_one_stage("misspelt")
    m.set_defaults(zetta=0.1)
    nd = gearsym.reduce(m)
    with pytest.raises(gearsym.UnknownParameterError, match=r"set_defaults.*'zetta'.*Did you mean 'zeta'") as err:
        nd.system()
    assert err.value.name == "zetta"


def test_parameter_without_default_names_it_and_its_definition():
    m = Drivetrain("nodefault")
    a = m.add(Gear("gear1", inertia="I1", base_radius="r1"))
    b = m.add(Gear("gear2", inertia="I2", base_radius="r2"))
    m.add(Mesh("mesh", a, b, variation="1 + k_a*cos(phi)"))
    m.add(Torque("M1", on=a, mean="M1", harmonics=(Harmonic("M1a", phase="Theta", group="B1"),)))
    m.set_defaults(omega=1.5, B0=1.0, B1=4.0, Theta=0.0, eta=10.0, k_a=0.2)  # zeta missing
    nd = gearsym.reduce(m)
    with pytest.raises(ModelError, match=r"without a default value: zeta \(.*cZ\*\(r2\*\*2/I2 \+ r1\*\*2/I1\)/2\)"):
        nd.system()
    with pytest.raises(ModelError, match=r"set_defaults\(zeta="):
        nd.defaults


@pytest.mark.parametrize("variation", ["1+0.2*cos(phi/2)", "1+0.2*sin(0.7*phi)", "1+phi/10"])
def test_variation_not_periodic(variation):
    m, a, b = pair()
    m.add(Mesh("wavy", a, b, variation=variation))
    with pytest.raises(ModelError, match=r"Mesh 'wavy'.*not 2\*pi-periodic"):
        m.form_eoms()


def test_periodic_variation_accepted():
    m, a, b = pair()
    m.add(Mesh("fine", a, b, variation="1+0.2*cos(2*phi)+0.1*sin(phi)"))
    assert len(m.form_eoms()) == 2


def test_unknown_function_in_formula():
    m, a, b = pair()
    m.add(Mesh("typo", a, b, variation="1+0.2*coss(phi)"))
    with pytest.raises(ModelError, match=r"Mesh 'typo'.*unknown function.*coss"):
        m.form_eoms()


def test_unknown_function_in_torque():
    m, a, b = pair()
    m.add(Mesh("mesh", a, b))
    m.add(Torque("drive", on=a, mean="M1*sqr(2)"))
    with pytest.raises(ModelError, match=r"Torque 'drive'.*unknown function.*sqr"):
        m.form_eoms()


@pytest.mark.parametrize("dup", [
    lambda: Gear("gear1", inertia="I9", base_radius="r9"),
    lambda: Mesh("gear2", "gear1", "gear2"),
    lambda: Torque("gear1", on="gear1", mean=1),
])
def test_duplicate_names(dup):
    m, a, b = pair()
    with pytest.raises(ModelError, match=r"gear[12]: .*already added"):
        m.add(dup())


def test_a_closed_loop_of_meshes_reduces_with_the_closing_deflection_a_combination_of_the_coordinates():
    m = Drivetrain("triangle")
    a = m.add(Gear("gear1", inertia="I1", base_radius="r1"))
    b = m.add(Gear("gear2", inertia="I2", base_radius="r2"))
    c = m.add(Gear("gear3", inertia="I3", base_radius="r3"))
    m.add(Mesh("m12", a, b))
    m.add(Mesh("m23", b, c))
    m.add(Mesh("m31", c, a))
    reduction = gearsym.reduce(m).reduction
    closing = reduction.deflections[2]
    assert [c.name for c in reduction.coordinates] == ["x1", "x2"]
    assert not closing.independent and sp.expand(closing.in_states()[0] + sp.Symbol("x1", real=True)
                                                 + sp.Symbol("x2", real=True)) == 0


def test_first_order_system_undeclared_symbol():
    with pytest.raises(gearsym.UnknownParameterError, match=r"lz: dx/dt: unknown parameter 'sigm'.*'sigma'"):
        FirstOrderSystem.from_equations("lz", ["x", "y"], ["sigm*(y - x)", "-x"], {"sigma": 10.0})


def test_first_order_system_undeclared_symbol_in_second_rhs():
    with pytest.raises(ModelError, match=r"dy/dt: unknown parameter 'q'"):
        FirstOrderSystem.from_equations("lz", ["x", "y"], ["y", "-x + q"], {"sigma": 10.0})


def test_first_order_system_unknown_parameter_in_with_values():
    lorenz = gearsym.load_model("lorenz")
    with pytest.raises(gearsym.UnknownParameterError, match="'rho'"):
        lorenz.with_values(rh0=1.0)


def test_errors_are_value_errors_and_carry_the_component():
    m, a, b = pair()
    m.add(Mesh("selfmesh", b, b))
    with pytest.raises(ValueError) as err:
        m.form_eoms()
    assert isinstance(err.value, gearsym.GearsymError)
    assert err.value.component == "Mesh 'selfmesh'"


# ---------------------------------------------------------------------------- physical signs
@pytest.mark.parametrize("field, value, what", [
    ("backlash", -1, "backlash must not be negative"),
    ("damping", "-0.1", "mesh damping must not be negative"),
])
def test_negative_mesh_property(field, value, what):
    m, a, b = pair()
    m.add(Mesh("mesh", a, b, **{field: value}))
    with pytest.raises(ModelError, match=rf"Mesh 'mesh'.*{what}"):
        m.form_eoms()


def test_negative_backlash_via_default():
    m = fresh_one_stage()
    m.set_defaults(eta=-1)
    with pytest.raises(ModelError, match=r"Mesh 'mesh'.*backlash must not be negative.*eta = -1"):
        m.form_eoms()


def test_negative_shaft_stiffness():
    m, a, b = pair()
    d = m.add(Disk("disk", inertia="I3"))
    m.add(Mesh("mesh", a, b))
    m.add(Shaft("shaft", b, d, stiffness=-0.1))
    with pytest.raises(ModelError, match=r"Shaft 'shaft'.*shaft stiffness must not be negative"):
        m.form_eoms()


@pytest.mark.parametrize("setting, message", [
    (dict(omega=0), r"'omega'.*forcing frequency and must be positive"),
    (dict(zeta=-0.1), r"'zeta'.*damping ratio and must not be negative"),
    (dict(eta=-2), r"'eta'.*backlash and must not be negative"),
    (dict(omega="fast"), r"'omega'.*must be a number"),
])
def test_run_time_values_are_checked(setting, message):
    nd = gearsym.reduce(fresh_one_stage())
    with pytest.raises(ModelError, match=message):
        nd.system(**setting)


def test_run_time_value_given_as_formula_string():
    nd = gearsym.reduce(fresh_one_stage())
    assert nd.system(omega="3/2").parameters["omega"] == 1.5
