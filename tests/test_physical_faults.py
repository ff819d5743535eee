"""A tooth fault on a model with physical values (issue 38): its depth is a dimensionless physical value."""
from __future__ import annotations

import pytest

import gearsym
from gearsym import Drivetrain, Gear, Mesh, ModelError, Torque, ToothFault


def cracked(**physical) -> Drivetrain:
    m = Drivetrain("cracked_si")
    pinion = m.add(Gear("pinion", inertia="I1", base_radius="r1", teeth=20, speed="speed"))
    wheel = m.add(Gear("wheel", inertia="I2", base_radius="r2", teeth=53))
    m.add(Mesh("mesh", pinion, wheel, variation="1 + 0.2*cos(phi)"))
    m.add(Torque("M1", on=pinion, mean="M1"))
    m.add(Torque("M2", on=wheel, mean="M2", load=True))
    m.add(ToothFault("crack", pinion, depth="q", tooth=3))
    m.set_physical(I1="4e-4 kg*m^2", I2="2e-2 kg*m^2", r1="20 mm", r2="53 mm", kZ="2e8 N/m", cZ="600 N*s/m",
                   eta="50 um", M1="100 N*m", M2="265 N*m", speed="3000 rpm", **physical)
    return m


def test_a_tooth_faults_depth_is_a_dimensionless_physical_value():
    system = gearsym.scaling(cracked(q=0.3)).system()
    assert system.parameters["q"] == pytest.approx(0.3) and system.cycles == 20  # a pinion revolution
    defaulted = cracked()
    defaulted.set_defaults(q=0.2)  # (a default serves as well, as for any dimensionless value)
    assert gearsym.scaling(defaulted).system().parameters["q"] == pytest.approx(0.2)
    with pytest.raises(ModelError, match="q"):
        gearsym.scaling(cracked(q="3 mm"))  # a length is not a fraction of stiffness
