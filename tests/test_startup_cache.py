"""A command on a model whose library is cached neither reduces it again nor imports SymPy (gearsym/cached.py)."""
from __future__ import annotations

import gc
import json
import os
import re
import subprocess
import sys

import pytest

import gearsym
import gearsym.loading  # noqa: F401 (where the face reduces a model: its reduce is counted too)
import gearsym.reduction  # noqa: F401 (the subpackage, whose reduce is counted)
import gearsym.units  # noqa: F401 (what a process learnt of units: a test starts it afresh)
from gearsym.cli import main
from gearsym.codegen import cache_dir
from gearsym.files.paths import REPO_ROOT

ARGS = ("--periods", "30", "--discard", "10", "--format", "json")


@pytest.fixture
def model_file(model_copy):
    """A copy of the one-stage model (see model_copy)."""
    return model_copy("one_stage")


@pytest.fixture
def model_copy(tmp_path, monkeypatch):
    """A shipped model copied into a file of its own, with a cache of its own for the summaries (the
    compiled libraries and code are the usual ones: nothing is compiled again)."""
    real = cache_dir()
    cache = tmp_path / "cache"
    cache.mkdir()
    for folder in ("lib", "code"):
        (real / folder).mkdir(parents=True, exist_ok=True)
        (cache / folder).symlink_to(real / folder)
    monkeypatch.setenv("GEARSYM_CACHE", str(cache))

    def copy(name: str):
        path = tmp_path / f"{name}_copy.py"
        path.write_text((REPO_ROOT / "models" / f"{name}.py").read_text())
        return path

    return copy


@pytest.fixture
def reductions(monkeypatch):
    """How many drivetrains were reduced."""
    count = []
    package = sys.modules["gearsym.reduction"]
    original = package.reduce

    def counting(*args, **kwargs):
        count.append(1)
        return original(*args, **kwargs)

    monkeypatch.setattr(package, "reduce", counting)
    monkeypatch.setattr(sys.modules["gearsym.loading"], "reduce", counting)
    return count


def lyap(capsys, *argv: str) -> dict:
    assert main(["lyap", *argv, *ARGS]) == 0
    return json.loads(capsys.readouterr().out)


def test_a_cached_model_is_not_reduced_again_and_gives_the_same_results(model_file, reductions, capsys):
    first = lyap(capsys, str(model_file), "--set", "omega=1.2")
    assert len(reductions) == 1
    again = lyap(capsys, str(model_file), "--set", "omega=1.2")
    assert len(reductions) == 1
    assert again == first


def test_a_changed_model_file_or_formula_is_reduced_again_and_a_new_plain_value_is_run_at_its_value(
        model_file, reductions, capsys):
    """A new plain value needs no reduction (its entry is derived from the model's own: test_a_derived_entry_...),
    but is run at that value; a formula or an edited model file is reduced again."""
    own = lyap(capsys, str(model_file))
    new_value = lyap(capsys, str(model_file), "--set", "omega=1.2")
    assert len(reductions) == 1
    assert new_value["parameters"]["omega"] == 1.2 and new_value["exponents"] != own["exponents"]
    lyap(capsys, str(model_file), "--set", "k=1+0.2*cos(tau)")
    assert len(reductions) == 2
    model_file.write_text(model_file.read_text().replace("omega=1.5", "omega=1.25"))
    changed = lyap(capsys, str(model_file))
    assert len(reductions) == 3
    assert changed["parameters"]["omega"] == 1.25


@pytest.mark.parametrize("name, values", [("one_stage", {"omega": 0.8}), ("one_stage", {"omega": 2.5, "zeta": 0.0}),
                                          ("flexible_shaft", {"omega": 1.3, "kS": 0.4}), ("duffing", {"omega": 1.7})])
def test_a_derived_entry_for_new_plain_values_is_the_entry_a_fresh_reduction_writes(model_copy, reductions, capsys,
                                                                                    tmp_path, monkeypatch, name,
                                                                                    values):
    """The summary derived from the model's own entry (gearsym/codegen/derived_summary.py) holds what the model
    loaded and reduced at the new values gives (its values, names, constraints, watches; the fastest mode and the
    period recomputed, to the rounding of the library's arithmetic), and the run prints what a run of a cache without
    the model's own entry prints."""
    from gearsym.codegen.fastest_mode import fastest_rate
    from gearsym.codegen.system_summary import SystemSummary

    import gearsym.cached as cached

    made, derive = [], cached.derived_entry
    monkeypatch.setattr(cached, "derived_entry", lambda *args: made.append(derive(*args)) or made[-1])
    path = model_copy(name)
    lyap(capsys, str(path))
    settings = [a for k, v in values.items() for a in ("--set", f"{k}={v}")]
    derived = lyap(capsys, str(path), *settings)
    assert len(made) == 1 and made[0] is not None and len(reductions) <= 1  # (duffing: a first-order system)
    entry = cached.cache_slot(str(path), values).system
    system = gearsym.load(str(path), **values)
    fresh = SystemSummary.of(system, False, fastest_rate(system)).as_dict()
    for key in ("fastest", "cycle"):
        assert entry.pop(key) == pytest.approx(fresh.pop(key), rel=1e-12, abs=0), key
    assert entry == fresh
    own_cache = tmp_path / "fresh-cache"  # (the libraries shared: the fresh run reduces, finds the library)
    own_cache.mkdir()
    for folder in ("lib", "code"):
        (own_cache / folder).symlink_to(cache_dir() / folder)
    monkeypatch.setenv("GEARSYM_CACHE", str(own_cache))
    assert lyap(capsys, str(path), *settings) == derived


def test_no_entry_is_derived_for_a_model_file_with_options(model_file, capsys):
    """A model option goes to the file's build, which may change the model (here it takes the name of a parameter,
    zeta, and leaves the model as it is): the model is loaded, as the option asks, not derived from its entry."""
    model_file.write_text(model_file.read_text() + "\nOPTIONS = {'zeta': 0.05}\n\n\ndef build(zeta=0.05):\n"
                          "    return model\n")
    own = lyap(capsys, str(model_file))
    assert lyap(capsys, str(model_file), "--set", "zeta=0.2")["parameters"] == own["parameters"]


def test_no_entry_is_derived_for_a_value_out_of_bounds_or_for_a_name_that_is_no_parameter(model_file, reductions,
                                                                                          capsys):
    """The model is loaded as before, whose error says what is wrong."""
    from gearsym.cached import cache_slot

    lyap(capsys, str(model_file))
    assert cache_slot(str(model_file), {"omega": 1.1}).system is not None
    for values in ({"zeta": -1.0}, {"omega": 1.1, "no_such_parameter": 2.0}):
        assert cache_slot(str(model_file), values).system is None, values
    assert main(["lyap", str(model_file), "--set", "zeta=-1", *ARGS]) == 2
    assert "zeta" in capsys.readouterr().err


def test_a_corrupt_summary_is_ignored_and_written_again(model_file, reductions, capsys):
    first = lyap(capsys, str(model_file))
    summaries = sorted((cache_dir() / "models").glob("*.json"))
    assert len(summaries) == 2
    for path in summaries:
        path.write_text(path.read_text()[:40])  # cut short, as by a crash without atomic writes
    assert lyap(capsys, str(model_file)) == first
    assert len(reductions) == 2
    assert all(json.loads(path.read_text())["format"] for path in summaries)
    assert lyap(capsys, str(model_file)) == first
    assert len(reductions) == 2


def lyap_text(capsys, *argv: str) -> str:
    assert main(["lyap", *argv, "--periods", "30", "--discard", "10"]) == 0
    return capsys.readouterr().out


@pytest.mark.slow
def test_a_cached_physical_model_is_not_reduced_again_and_prints_the_same(model_copy, reductions, capsys):
    spur = str(model_copy("spur_pair"))
    first_text, first_json = lyap_text(capsys, spur), lyap(capsys, spur)
    done = len(reductions)
    assert lyap_text(capsys, spur) == first_text
    assert lyap(capsys, spur) == first_json
    assert len(reductions) == done
    assert "operating point: 6000 rpm" in first_text and "mesh force mesh: mean" in first_text
    assert first_json["physical"]["mesh_force"]["mesh"]["mean"]["unit"] == "N"


def test_a_changed_physical_value_is_carried_back_with_the_new_value(model_copy, reductions, capsys):
    spur = str(model_copy("spur_pair"))
    lyap_text(capsys, spur)
    done = len(reductions)
    declared = gearsym.load_model(spur).physical["kZ"].si
    fourfold = f"kZ={4 * declared:.9g} N/m"  # 4 x the mesh stiffness: 2 x omega_n
    omega_n = float(re.search(r"omega_n = ([0-9.]+) Hz", lyap_text(capsys, spur)).group(1))
    stiffer = lyap_text(capsys, spur, "--set", fourfold)
    assert len(reductions) > done
    assert f"omega_n = {2 * omega_n:g} Hz" in stiffer
    assert lyap_text(capsys, spur, "--set", fourfold) == stiffer


FORMULA = ("--set", "k=1+0.2*cos(tau)")


@pytest.mark.parametrize("name, settings", [("one_stage", ()), ("spur_pair", ("--set", "speed=9100 rpm")),
                                            ("one_stage", FORMULA),
                                            ("spur_pair", (*FORMULA, "--plot", "{tmp}/point.png"))],
                         ids=["one_stage", "spur_pair at a speed in rpm (its unit read without pint)",
                              "a stiffness formula", "a formula and its figure in units"])
@pytest.mark.slow
def test_a_command_on_a_cached_model_imports_neither_sympy_pint_nor_casadi(model_copy, tmp_path, name, settings,
                                                                           capsys, monkeypatch):
    """The library is called through ctypes (its functions' sizes read from its own exports), the Jacobian for the
    resolution too, and a mesh's k(tau) is the summary's NumPy program: CasADi is for generating, not running."""
    model_file = model_copy(name)
    argv = [str(model_file), *(s.format(tmp=tmp_path) for s in settings), *ARGS]
    unplotted = [a for i, a in enumerate(argv) if "--plot" not in argv[max(i - 1, 0):i + 1]]

    def command(argv):  # a user's command on the cached model: a process of its own, whose imports are its own
        script = ("import sys; from gearsym.cli import main; "
                  f"main(['lyap', *{argv!r}]); "
                  "print(sorted(m for m in ('sympy', 'pint', 'casadi') if m in sys.modules), file=sys.stderr)")
        return subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, cwd=REPO_ROOT,
                              env={**os.environ, "PYTHONPATH": str(REPO_ROOT)}, timeout=120)

    # (fills the cache, in this process: without the figure, drawn once; the units this worker met earlier were kept
    # in other tests' caches, so it learns them again, as the user's first process does)
    monkeypatch.setattr(gearsym.units, "_KNOWN", {})
    first = lyap(capsys, *unplotted[:-len(ARGS)])
    run = command(argv)
    assert run.returncode == 0, run.stderr
    assert run.stderr.strip().splitlines()[-1] == "[]", run.stderr[-3000:]
    if unplotted != argv:
        assert (tmp_path / "point.png").read_bytes()[:4] == b"\x89PNG"
    assert json.loads(run.stdout) == first


@pytest.mark.slow
def test_an_orbit_of_a_cached_model_imports_neither_sympy_nor_pint(model_copy, capsys):
    """Its contact regime is read on the meshes the summary names (the reduction's couplings are not loaded)."""
    argv = ["orbits", str(model_copy("one_stage")), "--set", "omega=1.2"]
    assert main(argv) == 0  # (fills the cache, in this process)
    first = capsys.readouterr().out
    script = ("import sys; from gearsym.cli import main; "
              f"main({argv!r}); "
              "print(sorted(m for m in ('sympy', 'pint') if m in sys.modules), file=sys.stderr)")
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, cwd=REPO_ROOT,
                         env={**os.environ, "PYTHONPATH": str(REPO_ROOT)}, timeout=120)
    assert run.returncode == 0, run.stderr
    assert run.stderr.strip().splitlines()[-1] == "[]", run.stderr[-3000:]
    assert run.stdout == first
    assert "contact of mesh: single-sided impact" in run.stdout


def test_a_single_spectrum_loads_no_other_analysis():
    """What `gearsym lyap` imports (its command and the start-up cache) leaves out the runs from many starts, the
    lanes, the orders and their figures, and CasADi (the library is called through ctypes): each module is start-up
    time of every cached run (issue 39); and its classes are records, whose methods are not compiled when defined."""
    script = ("import sys, gearsym.cli.lyap, gearsym.cached; print(' '.join(sorted(sys.modules))); "
              "print(' '.join(sorted(f'{m}.{k}' for m, module in list(sys.modules.items()) if m.startswith('gearsym') "
              "for k, v in vars(module).items() if isinstance(v, type) and v.__module__ == m "
              "and getattr(getattr(v, '__init__', None), '__code__', None) is not None "
              "and v.__init__.__code__.co_filename == '<string>')))")
    loaded, generated = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, cwd=REPO_ROOT,
                                       env={**os.environ, "PYTHONPATH": str(REPO_ROOT)}, timeout=120,
                                       check=True).stdout.split("\n")[:2]
    loaded = set(loaded.split())
    assert "gearsym.analysis.lyapunov" in loaded and "gearsym.physical.point" in loaded
    unused = {"gearsym.analysis.attractors", "gearsym.analysis.basins", "gearsym.analysis.jumps",
              "gearsym.analysis.orders", "gearsym.analysis.order_run", "gearsym.analysis.lane_spectra",
              "gearsym.codegen.lane_runs", "gearsym.figures.poincare", "concurrent.futures", "sympy", "pint",
              "matplotlib", "casadi"}
    assert unused.isdisjoint(loaded), sorted(unused & loaded)
    # (a dataclass compiles its methods from text when defined, about a millisecond a class: these are records; but
    # LoopOptions, whose module's text is hashed into every model's generated C, which a change would regenerate)
    generated = set(generated.split()) - {"gearsym.codegen.loops.LoopOptions"}
    assert not generated, f"dataclasses on the cached path (declare them with records.record_class): {generated}"


def test_a_sweep_of_a_cached_model_chooses_its_step_without_reducing_it_again(model_file, reductions, tmp_path,
                                                                            capsys):
    """Its fastest end (omega = 0.1: 250 steps, the model's own values 200) is read from the cached library; the
    second sweep, a process of its own as a user's, imports neither SymPy nor CasADi (the Dask side, which ships
    models, loads the code generator only when a sweep runs there)."""
    argv = ["sweep", str(model_file), "--param", "omega=0.1:0.3:0.2", "--periods", "14", "--discard", "2", "--out"]

    def step(err: str) -> str:  # (the line that says the step and why)
        return next(line for line in err.splitlines() if line.startswith("gearsym: step:"))

    assert main([*argv, str(tmp_path / "first.csv")]) == 0
    first = step(capsys.readouterr().err)
    assert len(reductions) == 1 and "250 per forcing period" in first and "at omega=0.1:" in first
    script = ("import sys; from gearsym.cli import main; "
              f"status = main({[*argv, str(tmp_path / 'again.csv')]!r}); "
              "print(status, sorted(m for m in ('sympy', 'pint', 'casadi') if m in sys.modules), file=sys.stderr)")
    again = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, cwd=REPO_ROOT,
                           env={**os.environ, "PYTHONPATH": str(REPO_ROOT)}, timeout=120)
    assert again.stderr.strip().splitlines()[-1] == "0 []", again.stderr[-3000:]
    assert step(again.stderr) == first
    assert (tmp_path / "again.csv").read_text() == (tmp_path / "first.csv").read_text()


def test_a_chart_of_a_cached_model_runs_no_model_file_to_look_for_its_options(model_file, reductions, capsys,
                                                                              monkeypatch):
    """Its axes are parameters of the cached system, so neither is a model option (planets, dof): the model file is
    not run (SymPy not loaded) to say so, and the chart is the same."""
    argv = ["stability", str(model_file), "--param", "omega=0.5,1.5", "--param", "k_a=0.1", "--about", "orbit",
            "--format", "json", "--quiet"]
    def chart() -> dict:  # (but its timings)
        assert main(argv) == 0
        return {k: v for k, v in json.loads(capsys.readouterr().out).items() if k != "timings"}

    first = chart()
    assert len(reductions) == 1 and first["points"]

    def run_the_file(model):
        raise AssertionError(f"the model file {model} was run to read its options")

    monkeypatch.setattr(sys.modules["gearsym.cli.stability"], "model_options", run_the_file)
    assert chart() == first and len(reductions) == 1


@pytest.mark.slow
def test_a_formula_spelt_another_way_is_the_same_cached_model(model_file, reductions, capsys):
    first = lyap(capsys, str(model_file), *FORMULA)
    assert len(reductions) == 1
    assert lyap(capsys, str(model_file), "--set", " k =  1 + 0.2 * cos( tau ) ") == first
    assert len(reductions) == 1
    other = lyap(capsys, str(model_file), "--set", "k=1+0.25*cos(tau)")  # another formula: another model
    assert len(reductions) == 2 and other["exponents"] != first["exponents"]


@pytest.mark.slow
def test_a_sweep_of_a_cached_physical_model_is_carried_to_physical_units(model_copy, tmp_path, capsys):
    spur = str(model_copy("spur_pair"))
    lyap(capsys, spur, "--set", "speed=3000 rpm")
    out = tmp_path / "sweep.csv"
    run = subprocess.run([sys.executable, "-m", "gearsym.cli", "sweep", spur, "--param", "speed=3000rpm:6000rpm:3000rpm",
                          "--periods", "20", "--discard", "5", "--out", str(out)], capture_output=True, text=True,
                         cwd=REPO_ROOT, env={**os.environ, "PYTHONPATH": str(REPO_ROOT)}, timeout=120)
    assert run.returncode == 0, run.stderr[-2000:]
    assert out.with_suffix(".physical.csv").read_text().startswith("speed [rpm],")


def test_the_face_leaves_numpy_to_the_command_which_imports_with_the_collector_paused(monkeypatch, capsys):
    """``import gearsym`` (and the command line's module) imports no NumPy: the command imports it, with what it
    needs, while the garbage collector is paused (its collections among the imports had nothing to free); the
    objects then are set aside for good (gc.freeze) only in the command's own process, not in a caller's."""
    script = "import sys, gearsym, gearsym.cli; print('numpy' in sys.modules)"
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, cwd=REPO_ROOT,
                         env={**os.environ, "PYTHONPATH": str(REPO_ROOT)}, timeout=120, check=True)
    assert run.stdout.split() == ["False"]
    cli = sys.modules["gearsym.cli"]
    seen, frozen = [], []
    building = cli.build_parser

    def build_parser(command=None):
        seen.append(gc.isenabled())
        return building(command)

    monkeypatch.setattr(cli, "build_parser", build_parser)
    monkeypatch.setattr(gc, "freeze", lambda: frozen.append(1))
    assert main(["list"]) == 0 and seen == [False] and gc.isenabled() and not frozen
    monkeypatch.setattr(sys, "argv", ["gearsym", "list"])
    assert main() == 0 and seen == [False, False] and gc.isenabled() and frozen == [1]
    capsys.readouterr()


@pytest.mark.parametrize("given", [{}, {"OMP_NUM_THREADS": "2"}, {"OPENBLAS_NUM_THREADS": "2"}])
def test_the_command_runs_numpys_blas_on_one_thread_unless_told_otherwise(given, capsys):
    """Set before NumPy is imported, in the command's own process only (its pool of threads was a tenth of a cached
    model's start-up); a thread count the user set is kept. (A caller's process: the test after this one.) The
    command: a spectrum of a cached model (cached here first), which runs NumPy's linear algebra."""
    lyap(capsys, "one_stage")
    script = ("import os, sys; from gearsym.cli import main; "
              f"sys.argv = ['gearsym', 'lyap', 'one_stage', *{ARGS!r}]; "
              "main(); print([os.environ.get(k) for k in ('OPENBLAS_NUM_THREADS', 'OMP_NUM_THREADS')])")
    env = {k: v for k, v in os.environ.items() if not k.endswith("_NUM_THREADS")}
    run = subprocess.run([sys.executable, "-c", script],
                         capture_output=True, text=True, cwd=REPO_ROOT, timeout=120, check=True,
                         env={**env, **given, "PYTHONPATH": str(REPO_ROOT)})
    told = [given.get("OPENBLAS_NUM_THREADS", "1" if not given else None), given.get("OMP_NUM_THREADS")]
    assert run.stdout.strip().splitlines()[-1] == repr(told)


def test_a_caller_of_main_keeps_its_blas_threads_as_they_were(monkeypatch, capsys):
    """main(argv) called from a caller's process (a notebook, a script) leaves the caller's environment alone."""
    for name in [k for k in os.environ if k.endswith("_NUM_THREADS")]:
        monkeypatch.delenv(name)
    assert lyap(capsys, "one_stage")["exponents"]
    assert not [k for k in os.environ if k.endswith("_NUM_THREADS")]
