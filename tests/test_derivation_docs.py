"""The committed derivation pages (docs/derivations/<model>.md) and the derivation renderers.

The regression test the project relies on: regenerating every page gives the
committed file byte for byte. If it fails after a deliberate change, run
``gearsym docs --all`` and review the diff.
"""
from __future__ import annotations

import functools
import json
import os
import re
import subprocess
import sys

import pytest
import sympy as sp

import conftest
from gearsym import Drivetrain, GearsymError, load_model
from gearsym.registry import pregenerated_models
from gearsym.model.backlash import g
from gearsym.derivation import FORMATS, Derivation, derive, render
from gearsym.files.paths import REPO_ROOT
from gearsym.model.symbols import parameter_symbol

DOCS = REPO_ROOT / "docs" / "derivations"
MODELS = pregenerated_models("page")  # (the models whose pages are committed)
GEAR_MODELS = [m for m in MODELS if isinstance(conftest.load(m), Drivetrain)]


@functools.cache
def derivation(model: str) -> Derivation:
    """Reducing takes seconds: one derivation per model for the whole session (from the session's reduction)."""
    declared = conftest.load(model)
    return derive(conftest.reduced(model) if isinstance(declared, Drivetrain) else declared)


@functools.cache
def page(model: str) -> str:
    return render(derivation(model), "markdown")


def test_the_models_are_the_expected_ones():
    assert set(MODELS) >= {"one_stage", "one_stage_resonant", "flexible_shaft", "two_stage", "lorenz"}


@pytest.mark.parametrize("model", conftest.model_params(MODELS))
@pytest.mark.slow
def test_committed_page_is_regenerated_byte_for_byte(model):
    path = DOCS / f"{model}.md"
    assert path.is_file(), f"{path} is missing: run `gearsym docs --all`"
    assert path.read_bytes() == page(model).encode("utf-8"), f"{path} is out of date: run `gearsym docs {model}`"


def test_no_page_without_a_model():
    assert sorted(p.stem for p in DOCS.glob("*.md")) == MODELS


@pytest.mark.parametrize("model", ["one_stage", "lorenz"])
@pytest.mark.parametrize("fmt", sorted(FORMATS))
def test_rendering_twice_is_identical(model, fmt):
    d = derivation(model)
    first = render(d, fmt, full=True)
    assert first == render(d, fmt, full=True)
    assert first == render(derive(load_model(model)), fmt, full=True)  # a fresh derivation of the declared model


@pytest.mark.slow
def test_page_does_not_depend_on_the_hash_seed():
    """Set iteration order changes with PYTHONHASHSEED; the page must not."""
    code = ("import sys, gearsym; from gearsym.derivation import derive, render; "
            "sys.stdout.write(render(derive(gearsym.load_model('one_stage')), 'markdown'))")
    env = {**os.environ, "PYTHONHASHSEED": "4242", "PYTHONIOENCODING": "utf-8"}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, env=env, check=True, cwd=REPO_ROOT)
    assert out.stdout == page("one_stage").encode("utf-8")


# ------------------------------------------------------------------ page content
@pytest.mark.slow
@pytest.mark.parametrize("model", conftest.model_params(MODELS))
def test_page_header_and_no_run_dependent_text(model):
    text = page(model)
    first = text.splitlines()[0]
    assert f"gearsym docs {model}" in first and "do not edit by hand" in first
    assert str(REPO_ROOT) not in text and "/home/" not in text and "/tmp" not in text
    assert text.endswith("\n") and not text.endswith("\n\n")
    assert "\r" not in text


@pytest.mark.parametrize("model", conftest.model_params(GEAR_MODELS))
def test_gear_page_has_every_section(model):
    headings = [line[3:] for line in page(model).splitlines() if line.startswith("## ")]
    physical = ["Physical values and scaling"] if load_model(model).physical else []
    assert headings == [
        "Components", "Lagrangian", "Equations of motion", "Rigid-body modes", "Coordinate change",
        "Reduced equations", "Coefficient groups and conditions", "Nondimensional equations", *physical,
        "First-order system", "Parameters", "Notes on the paper",
    ]


def test_lorenz_page_has_only_the_first_order_system():
    text = page("lorenz")
    headings = [line[3:] for line in text.splitlines() if line.startswith("## ")]
    assert headings == ["First-order system", "Parameters"]
    assert r"\dot{x} &= \sigma \left(- x + y\right)" in text
    assert "| `beta` | $\\beta$ | 2.66666666667 | geometric factor |" in text


def _math_segments(text: str) -> tuple[list[str], list[str]]:
    """(display blocks, inline spans) of a page."""
    lines = text.splitlines()
    display, inline, block = [], [], None
    for line in lines:
        if line == "$$":
            if block is None:
                block = []
            else:
                display.append("\n".join(block))
                block = None
        elif block is not None:
            block.append(line)
        else:
            inline += re.findall(r"\$([^$]+)\$", re.sub(r"`[^`]*`", "", line))
    assert block is None, "unclosed $$ block"
    return display, inline


@pytest.mark.parametrize("model", conftest.model_params(MODELS))
def test_math_is_safe_for_github(model):
    """What GitHub's Markdown pass could mangle before MathJax sees it."""
    text = page(model)
    lines = text.splitlines()
    for i, line in enumerate(lines):
        if "$$" in line:
            assert line == "$$", f"line {i + 1}: $$ must be alone on its line"
    opening = [i for i, line in enumerate(lines) if line == "$$"][::2]
    closing = [i for i, line in enumerate(lines) if line == "$$"][1::2]
    for i in opening:
        assert lines[i - 1] == "", f"line {i + 1}: no blank line before $$"
    for i in closing:
        assert i + 1 == len(lines) or lines[i + 1] == "", f"line {i + 1}: no blank line after $$"
    display, inline = _math_segments(text)
    assert display and inline
    for tex in display + inline:
        assert "}_" not in tex, tex  # Markdown could read it as an emphasis delimiter
        assert "*" not in tex, tex
        assert not re.search(r"\\[!-/:-@\[\]^_`{|}~]", tex.replace("\\\\\n", "")), f"backslash escape in {tex}"
        assert tex.count("{") == tex.count("}"), tex
        for env in re.findall(r"\\begin\{(\w+)\}", tex):
            assert env in {"aligned", "bmatrix"}, env
    for tex in display:
        assert "\n\n" not in tex
        for row in tex.splitlines():
            assert not re.match(r"\s*([-+*=#>]|\d+[.)])", row), f"Markdown could read {row!r} as a block"
        assert tex.count("\\\\") == tex.count("\\\\\n"), "every \\\\ must end its line"
    for tex in inline:
        assert "\\\\" not in tex and "|" not in tex


def test_flexible_shaft_page_shows_the_paper_equations():
    text = page("flexible_shaft")
    # Eq. 8 (second body) and Eq. 9, in the paper's layout
    assert r"I_{2} \ddot{\psi_{2}} - c_{Z} r_{2} \left(r_{1} \dot{\psi_{1}} - r_{2} \dot{\psi_{2}}\right)" in text
    assert (r"\frac{d^{2} x_{2}}{d \tau^{2}} + \frac{\beta_{2} k_{S} x_{2}}{\omega^{2}} + "
            r"\frac{2 \beta_{3} \zeta \frac{d x_{1}}{d \tau}}{\omega} + "
            r"\frac{\beta_{3} k\left(\tau\right) g\left(x_{1}, \eta\right)}{\omega^{2}} &= 0") in text
    # Eq. 10 as a groups table and the torque-balance condition
    assert r"| $\beta_{1}$ | $\frac{1}{I_{2}}$ | derived | 1 |" in text
    assert r"| $\beta_{2}$ | $\frac{1}{I_{3}} + \frac{1}{I_{2}}$ | derived | 2 |" in text
    assert r"0 &= - \frac{M_{3} r_{2}}{I_{3}} + \frac{M_{2} r_{2}}{I_{2}}" in text
    # the coordinate change of the paper: x1 = r1 psi1 - r2 psi2, x2 = r2 (psi3 - psi2)
    assert r"x_{1} &= r_{1} \psi_{1} - r_{2} \psi_{2}" in text
    assert r"x_{2} &= - r_{2} \psi_{2} + r_{2} \psi_{3}" in text
    assert "| `kS` | $k_{S}$ | 0.1 |" in text


@pytest.mark.parametrize("model", conftest.model_params(GEAR_MODELS))
def test_notes_on_the_paper(model):
    notes = derivation(model).notes
    assert any("x ≤ −η" in n and "x ≤ η" in n for n in notes)
    computed = [c for c in conftest.load(model).couplings if getattr(c, "computed", None) is not None]
    assert any("rectangular_mesh_stiffness" in n and "contact ratio 1.6" in n and "7 Fourier harmonics" in n
               and "= 0.2" in n for n in notes) == (not computed)
    assert all(any("from the gears' geometry" in n and "7 Fourier harmonics with Lanczos factors" in n
                   and f"contact ratio {c.computed.curve.contact_ratio:.4f}" in n for n in notes) for c in computed)
    assert any(n.startswith("Time unit") for n in notes)
    assert any(n.startswith("Inertias and radii") for n in notes) == (model in {"flexible_shaft", "two_stage"}
                                                                       or model.startswith("planetary"))
    assert any(n.startswith("Torque balance") for n in notes) == (model == "flexible_shaft")


def test_notes_give_the_values_behind_beta():
    (note,) = [n for n in derivation("flexible_shaft").notes if n.startswith("Inertias")]
    assert "I1 = 1, I2 = 1, I3 = 1, r1 = 1, r2 = 1" in note
    assert "beta_1 = 1, beta_2 = 2, beta_3 = 0.5" in note


# ------------------------------------------------------------------ the record and other formats
def test_derivation_record_of_flexible_shaft():
    d = derivation("flexible_shaft")
    m = d.mechanics
    I2, I3, r1, r2 = (parameter_symbol(n) for n in ("I2", "I3", "r1", "r2"))
    groups = {gr.name: gr for gr in m.groups}
    assert sp.simplify(groups["beta_2"].definition - (1 / I2 + 1 / I3)) == 0
    assert groups["beta_3"].value == pytest.approx(0.5)
    assert [b.name for b in m.bodies] == ["gear1", "gear2", "disk3"]
    assert [(c.name, c.kind, c.ends, c.coordinate) for c in m.couplings] == [
        ("mesh", "mesh", ("gear1", "gear2"), "x1"), ("shaft", "shaft", ("gear2", "disk3"), "x2"),
    ]
    assert [(tq.name, tq.load, len(tq.terms)) for tq in m.torques] == [("M1", False, 2), ("M2", True, 1), ("M3", True, 1)]
    assert len(m.equations_of_motion) == 3 and len(m.reduced_equations) == 2 and len(m.equations) == 2
    assert len(m.rigid_modes) == 1 and list(m.rigid_modes[0]) == [r2, r1, r1]
    assert [s.name for s in d.states] == ["x1", "v1", "x2", "v2"]
    assert d.period == 2 * sp.pi
    assert [p.name for p in d.parameters][:4] == ["omega", "zeta", "B0", "B1"]


def test_latex_uses_the_paper_notation():
    tex = render(derivation("one_stage"), "latex", full=True)
    assert r"g\left(x, \eta\right)" in tex
    assert r"\frac{d^{2} x}{d \tau^{2}} + \frac{2 \zeta \frac{d x}{d \tau}}{\omega}" in tex
    assert r"I_{1} \ddot{\psi_{1}}" in tex and r"k_{Z}\left(t\right)" in tex
    assert r"\zeta &= \frac{c_{Z} \left(\frac{r_{2}^{2}}{I_{2}} + \frac{r_{1}^{2}}{I_{1}}\right)}{2}" in tex
    assert r"\psi_{1}{\left(t \right)}" not in tex  # coordinates are written without their argument


def test_text_shows_equations_groups_and_parameters():
    text = render(derivation("flexible_shaft"), "text")
    assert "Nondimensional equations" in text and "Coefficient groups" in text
    assert "β₃" in text and "[derived] share of mesh 'mesh' force in x2 (value at the defaults: 0.5)" in text
    assert re.search(r"^  kS +0\.1  torsional stiffness", text, re.M)
    assert "Lagrangian" not in text
    full = render(derivation("flexible_shaft"), "text", full=True)
    assert "Lagrangian" in full and "Notes on the paper" in full


def test_json_has_everything_and_parses_back():
    data = json.loads(render(derivation("two_stage"), "json"))
    assert data["states"] == ["x1", "v1", "x2", "v2", "x3", "v3"]
    assert data["period"] == "4*pi"
    assert {gr["name"]: gr["kind"] for gr in data["groups"]}["K2"] == "free"
    assert data["parameters"]["I4"] == {"default": 9.0, "description": "moment of inertia of 'gear4'"}
    eq = sp.sympify(data["equations"][2], locals={"g": g})
    assert isinstance(eq, sp.Eq)
    assert data["components"]["couplings"][2]["mesh_phase"] == "omega*t/2"
    assert len(data["equations_of_motion"]) == 4 and data["lagrangian"]["T"].startswith("I1*")


def test_unknown_format_is_a_gearsym_error():
    with pytest.raises(GearsymError, match="Did you mean 'json'"):
        render(derivation("lorenz"), "jsn")
