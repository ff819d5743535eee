"""Formula strings are read, never run as Python (issue 12).

Every entry that turns a string into an expression (``--set``, model files,
``FirstOrderSystem.from_equations``, ``gearsym.load(model, k=...)``) goes
through :func:`gearsym.model.formula.parse_formula`; the payloads here would run
shell commands if any of them reached ``eval``, ``sympify`` or ``parse_expr``.
"""
from __future__ import annotations

import casadi as ca
import pytest
import sympy as sp

import gearsym
from conftest import reduced
from gearsym import Drivetrain, FirstOrderSystem, Gear, Mesh, ModelError, Torque
from gearsym.cli import main
from gearsym.codegen.translate import to_casadi
from gearsym.model.expressions import to_expr
from gearsym.model.stiffness import rectangular_mesh_stiffness
from gearsym.model.symbols import omega, parameter_symbol, phi, t, tau

TOUCH = "__import__('os').system('touch PWNED')"
ECHO = "__import__('os').system('echo PWNED')"


@pytest.fixture
def sandbox(tmp_path, monkeypatch):
    """A working directory in which a payload that ran would leave the file PWNED."""
    monkeypatch.chdir(tmp_path)
    yield tmp_path
    assert not (tmp_path / "PWNED").exists(), "a formula was run as Python"


@pytest.mark.parametrize("argv", [
    ["lyap", "one_stage", "--set", f"omega={TOUCH}+1.5"],
    ["lyap", "one_stage", "--set", f"k={ECHO}"],
    ["lyap", "one_stage", "--set", f"k=1+0.2*cos(tau)+{TOUCH}"],
    ["sweep", "one_stage", "--param", "omega=1,2", "--set", f"zeta={TOUCH}", "--out", "out.csv"],
    ["compile", "one_stage", "--set", f"k_a={TOUCH}"],
    ["sweep", "one_stage", "--param", "omega=1", "--y0", f"x={TOUCH}", "--out", "out.csv"],
    ["sweep", "one_stage", "--param", f"omega={TOUCH}", "--out", "out.csv"],
])
def test_the_issue_injections_stop_the_cli_with_one_line_and_run_nothing(argv, sandbox, capfd):
    code = main(argv)
    out, err = capfd.readouterr()  # file descriptors: a shell command's echo would show here
    assert code == 2
    assert "PWNED" not in out
    assert err.startswith("gearsym: error: ") and err.count("\n") == 1 and "Traceback" not in err


def test_the_set_error_names_the_option_and_what_was_refused(sandbox, capsys):
    assert main(["lyap", "one_stage", "--set", f"omega={TOUCH}+1.5"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("gearsym: error: --set omega: the formula ")
    assert "attribute access (.)" in err and "sin, cos" in err


@pytest.mark.parametrize("formula, refused", [
    (TOUCH, "attribute access"),
    ("().__class__.__bases__[0].__subclasses__()", "attribute access"),
    ("x.__class__", "attribute access"),
    ("os.system", "attribute access"),
    ("__import__('os')", "'__import__'; a name in a formula must not start with '_'"),
    ("__builtins__", "'__builtins__'; a name in a formula must not start with '_'"),
    ("eval('1')", "unknown function eval()"),
    ("exec('import os')", "unknown function exec()"),
    ("getattr(x, 'real')", "unknown function getattr()"),
    ("lambda: 1", "uses lambda"),
    ("x[0]", "subscripts"),
    ("'touch PWNED'", "the constant 'touch PWNED'"),
    ("b'x'", "the constant b'x'"),
    ("sin(x=1)", "keyword argument"),
    ("sin(*x)", "unpacking"),
    ("[x for x in y]", "comprehension"),
    ("f'{x}'", "f-string"),
    ("(x := 1)", "':='"),
    ("x if y else z", "Piecewise"),
    ("x^2", r"'^' (write powers as **)"),
    ("2j", "imaginary"),
    ("x and y", "use And(a, b)"),
    ("sin(x)(2)", "calls something other than a function by its name"),
    ("(1 + x)(2)", "calls something other than a function by its name"),
])
def test_a_formula_that_reaches_outside_the_grammar_is_refused_in_one_line(formula, refused, sandbox):
    with pytest.raises(ModelError) as err:
        to_expr(formula, "Mesh 'm'")
    message = str(err.value)
    assert message.startswith("Mesh 'm': ") and refused in message and "\n" not in message


@pytest.mark.parametrize("formula, refused", [
    ("1+" * 50_000 + "1", "has 100001 characters, more than the 10000 a formula may have"),
    ("(" * 500 + "x" + ")" * 500, "nested too deeply"),
    ("-" * 5000 + "x", "nested too deeply"),
    ("sin(" * 150 + "x" + ")" * 150, "nested too deeply"),
    ("+".join(["x"] * 3000), "nested too deeply"),
    ("2**2**2**2**2**2", "too large to compute exactly"),
    ("10**10**10", "too large to compute exactly"),
])
def test_huge_or_deeply_nested_formulas_are_refused_without_a_traceback(formula, refused):
    with pytest.raises(ModelError) as err:
        to_expr(formula, "--set k")
    message = str(err.value)
    assert refused in message and len(message) < 1000


def test_from_equations_runs_no_formula(sandbox):
    with pytest.raises(ModelError, match=r"duffing: dv/dt: the formula .* attribute access"):
        FirstOrderSystem.from_equations("duffing", ["x", "v"], ["v", f"-x + {TOUCH}"], {}, period="2*pi")


def test_a_mesh_variation_in_a_drivetrain_runs_no_formula(sandbox):
    m = Drivetrain("hostile")
    a = m.add(Gear("gear1", inertia="I1", base_radius="r1"))
    b = m.add(Gear("gear2", inertia="I2", base_radius="r2"))
    m.add(Mesh("mesh", a, b, variation=f"1 + 0.2*cos(phi) + {TOUCH}"))
    with pytest.raises(ModelError, match=r"Mesh 'mesh'.*attribute access"):
        m.form_eoms()


def test_a_torque_in_a_drivetrain_runs_no_formula(sandbox):
    m = Drivetrain("hostile")
    a = m.add(Gear("gear1", inertia="I1", base_radius="r1"))
    b = m.add(Gear("gear2", inertia="I2", base_radius="r2"))
    m.add(Mesh("mesh", a, b))
    m.add(Torque("drive", on=a, mean=f"M1 + {TOUCH}"))
    with pytest.raises(ModelError, match=r"Torque 'drive'.*attribute access"):
        m.form_eoms()


@pytest.mark.parametrize("setting", ["k", "omega"])
def test_load_runs_no_formula(setting, sandbox):
    with pytest.raises(ModelError, match="attribute access"):
        gearsym.load(reduced("one_stage"), **{setting: f"1 + {TOUCH}"})


def test_the_code_generator_takes_no_strings(sandbox):
    x = sp.Symbol("x", real=True)
    with pytest.raises(ModelError, match="expected a SymPy expression"):
        to_casadi([f"x + {TOUCH}"], {x: ca.SX.sym("x")})
    assert str(to_casadi([x + 1, 2, 0.5], {x: ca.SX.sym("x")})) == "[SX((1+x)), SX(2), SX(0.5)]"



@pytest.mark.slow
def test_no_module_hands_sympify_what_it_could_run():
    """Every sympify in the package is strict (numbers and SymPy objects only: a string is refused, never parsed as
    Python), so a value that comes from a model file, the cache or a record can reach none as code."""
    import ast

    from gearsym.files.paths import PACKAGE_DIR as PACKAGE_ROOT

    loose = []
    for path in sorted(PACKAGE_ROOT.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Call) and getattr(node.func, "attr", getattr(node.func, "id", "")) == "sympify" \
                    and not any(k.arg == "strict" and getattr(k.value, "value", False) is True for k in node.keywords):
                loose.append(f"{path.relative_to(PACKAGE_ROOT)}:{node.lineno}")
    assert loose == []
    from gearsym.reduction.statics import number  # (one of them, handed a string as a record could)
    with pytest.raises(sp.SympifyError):
        number(TOUCH, {}, "a stiffness")


def _p(*names):
    return [parameter_symbol(n) for n in names]


def _expected():
    kv, kw, sigma, x, y, beta, zeta, gamma, E, I, a = _p("kv", "kw", "sigma", "x", "y", "beta", "zeta", "gamma",
                                                        "E", "I", "a")
    return [
        ("1+0.2*cos(tau)", 1 + sp.Float("0.2") * sp.cos(tau)),
        ("1 + kv*cos(phi) + kw*sin(2*phi)", 1 + kv * sp.cos(phi) + kw * sp.sin(2 * phi)),
        ("sigma*(y-x)", sigma * (y - x)),
        ("beta*zeta + gamma - E*I", beta * zeta + gamma - E * I),
        ("2*pi/omega + t", 2 * sp.pi / omega + t),
        ("1/2 + 2**-1", sp.Integer(1)),
        ("-0.5 + 1e-3 + 2**0.5", sp.Float("-0.5") + sp.Float("1e-3") + sp.Integer(2) ** sp.Float("0.5")),
        ("0.12345678901234567890*a", sp.Float("0.12345678901234567890") * a),
        ("x**2**3", x ** 8),
        ("abs(x) + Abs(y) + sqrt(x)", sp.Abs(x) + sp.Abs(y) + sp.sqrt(x)),
        ("Piecewise((x**3, x > 0), (x, True))", sp.Piecewise((x ** 3, x > 0), (x, True))),
        ("Heaviside(x) + Min(x, 1) + Max(x, -1) + atan2(y, x)",
         sp.Heaviside(x) + sp.Min(x, 1) + sp.Max(x, -1) + sp.atan2(y, x)),
        (str(rectangular_mesh_stiffness()), rectangular_mesh_stiffness()),
    ]


@pytest.mark.parametrize("formula, expected", _expected(), ids=lambda v: v if isinstance(v, str) else "")
def test_the_formulas_in_use_read_as_the_same_sympy_expressions(formula, expected):
    assert sp.srepr(to_expr(formula, "test")) == sp.srepr(expected)  # the same tree, assumptions, float precision


def test_comparisons_read_as_sympy_relations_not_as_python_truth_values():
    x = parameter_symbol("x")
    assert to_expr("0 < x <= 1", "test") == sp.And(sp.Lt(0, x), sp.Le(x, 1))  # Python would ask bool(0 < x)
    assert to_expr("x == 1", "test") == sp.Eq(x, 1)  # Python's == would compare the trees: False
    assert to_expr("x != 1", "test") == sp.Ne(x, 1)
