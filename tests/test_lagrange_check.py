"""The reduction's self-check against Lagrange's equations (gearsym.reduction.reduction.check_against_lagrange) is a
real check: at random states it passes every reduction as derived and fails one with an error planted in it, a
coupling's factor, a forcing's coefficient, a turning frame's force or a coupling's law, each off by a part in a
million, and names the row or the coupling.
"""
from __future__ import annotations

from dataclasses import replace

import pytest
import sympy as sp

from conftest import reduced, slow_models_group
from gearsym.reduction import ReductionError
from gearsym.reduction import reduction as reduction_module
from gearsym.reduction.reduction import Reduction, check_against_lagrange

OFF = sp.Rational(1, 10**6)


def planted(red: Reduction, **changes) -> Reduction:
    """A copy of ``red`` (its cached equations not carried over) with ``changes``."""
    return Reduction(red.drivetrain, red.resolved, red.coordinates, red.transform, red.rigid_modes, red.deflections,
                     changes.get("coupling_terms", red.coupling_terms), changes.get("forcing_terms", red.forcing_terms),
                     changes.get("frame_rows", red.frame_rows))


@pytest.mark.parametrize("name", ["spur_pair_bearings", "two_stage"])
def test_the_check_passes_a_reduction_as_derived_and_fails_a_coupling_factor_off_by_a_part_in_a_million(name):
    red = reduced(name).reduction
    check_against_lagrange(planted(red))
    terms = list(red.coupling_terms)
    k = len(terms) // 2
    terms[k] = replace(terms[k], factor=terms[k].factor * (1 + OFF))
    with pytest.raises(ReductionError, match=f"reduced equation of {red.coordinates[terms[k].row].name} "):
        check_against_lagrange(planted(red, coupling_terms=terms))


def test_the_check_fails_a_forcing_coefficient_off_by_a_part_in_a_million():
    red = reduced("spur_pair_bearings").reduction
    terms = list(red.forcing_terms)
    terms[0] = replace(terms[0], coefficient=terms[0].coefficient * (1 + OFF))
    with pytest.raises(ReductionError, match="does not give Lagrange's acceleration"):
        check_against_lagrange(planted(red, forcing_terms=terms))


def test_the_check_names_the_coupling_whose_law_is_not_lagranges(monkeypatch):
    red = reduced("spur_pair_bearings").reduction
    mesh = next(rc for rc in red.resolved.couplings if rc.kind == "mesh")
    law = reduction_module._law_in_angles
    monkeypatch.setattr(reduction_module, "_law_in_angles",
                        lambda rd, rc: law(rd, rc) * (1 + OFF) if rc is mesh else law(rd, rc))
    with pytest.raises(ReductionError, match=f"{mesh.name}: its generalized forces are not its law"):
        check_against_lagrange(planted(red))


@pytest.mark.slow
@slow_models_group()
def test_the_check_fails_a_turning_frames_force_off_by_a_part_in_a_million():
    red = reduced("planetary_translational").reduction
    assert red.frame_rows and any(row != 0 for row in red.frame_rows)
    check_against_lagrange(planted(red))
    k = next(i for i, row in enumerate(red.frame_rows) if row != 0)
    rows = list(red.frame_rows)
    rows[k] = rows[k] * (1 + OFF)
    with pytest.raises(ReductionError, match=f"reduced equation of {red.coordinates[k].name} "):
        check_against_lagrange(planted(red, frame_rows=rows))
