"""gearsym as anyone installs it: a wheel, installed (not editable) into a fresh virtual environment, runs the
shipped models from another folder with the committed C it carries, and gives what the clone gives.

The wheel is built from a copy of the files a build reads (no stale ``build/`` of the clone gets in) with this
environment's setuptools, and installed with pip, without the network: the new environment reads this one's
site-packages as plain folders (a ``.pth`` of paths), so its dependencies are this environment's while its
gearsym is the wheel's alone (this environment's editable gearsym comes through an import hook that a plain
folder does not run)."""
from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from gearsym.cli import main
from gearsym.codegen import cache_dir
from gearsym.files.paths import REPO_ROOT

pytestmark = pytest.mark.slow

#: what a build of the wheel reads (pyproject.toml and setup.py say what of it goes in)
BUILD_INPUTS = ("pyproject.toml", "setup.py", "README.md", "gearsym", "models", "generated")
LYAP = ("lyap", "one_stage", "--periods", "60", "--discard", "20", "--format", "json")


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    source = tmp_path_factory.mktemp("source")
    for name in BUILD_INPUTS:
        if (REPO_ROOT / name).is_dir():
            shutil.copytree(REPO_ROOT / name, source / name, ignore=shutil.ignore_patterns("__pycache__", "*.so"))
        else:
            shutil.copy2(REPO_ROOT / name, source / name)
    out = tmp_path_factory.mktemp("dist")
    run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "--no-index", "-q", "-w",
         str(out), str(source)])
    (built,) = out.glob("gearsym-*.whl")
    return built


@pytest.fixture(scope="module")
def installed(wheel, tmp_path_factory) -> Path:
    """The ``bin`` folder of a fresh virtual environment with the wheel installed in it."""
    venv = tmp_path_factory.mktemp("venv")
    run([sys.executable, "-m", "venv", "--without-pip", str(venv)])
    python = venv / "bin" / "python"
    site = Path(run([str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"]).strip())
    # this environment's folders, as plain paths: not its .pth files (its editable gearsym), not the clone
    folders = [p for p in sys.path if p and Path(p).is_dir() and Path(p).resolve() != REPO_ROOT]
    (site / "runner.pth").write_text("\n".join(folders) + "\n")
    run([str(python), "-m", "pip", "install", "--no-deps", "--no-index", "-q", str(wheel)])
    return venv / "bin"


def run(argv, cwd=None, env=None) -> str:
    proc = subprocess.run(argv, capture_output=True, text=True, cwd=cwd, env=env, timeout=600)
    assert proc.returncode == 0, f"{' '.join(map(str, argv))}\n{proc.stdout[-2000:]}\n{proc.stderr[-4000:]}"
    return proc.stdout


@pytest.fixture
def elsewhere(tmp_path):
    """A folder with nothing of gearsym's, and a cache of its own whose libraries are this session's (the
    committed C compiles to the same library: nothing is compiled again) but whose generated code is not."""
    cache = tmp_path / "cache"
    cache.mkdir(mode=0o700)
    real = cache_dir()
    (real / "lib").mkdir(parents=True, exist_ok=True)
    (cache / "lib").symlink_to(real / "lib")
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    work = tmp_path / "work"
    work.mkdir()
    return work, {**env, "GEARSYM_CACHE": str(cache)}


def test_the_wheel_carries_the_shipped_models_and_their_c_inside_gearsym(wheel):
    names = zipfile.ZipFile(wheel).namelist()
    assert {n.split("/")[0] for n in names} == {"gearsym", wheel.name.split("-py3")[0] + ".dist-info"}, \
        "something of gearsym's wheel lands at the top of site-packages"
    models = {p.name for p in (REPO_ROOT / "models").glob("*.py")}
    assert {n.split("/")[-1] for n in names if n.startswith("gearsym/shipped/models/")} == models
    committed = {str(p.relative_to(REPO_ROOT / "generated")) for p in (REPO_ROOT / "generated").glob("*/*")}
    assert {n.removeprefix("gearsym/shipped/generated/") for n in names
            if n.startswith("gearsym/shipped/generated/")} >= committed


def test_an_installed_wheel_lists_and_runs_the_shipped_models_from_another_folder(installed, elsewhere, capsys):
    work, env = elsewhere
    where = json.loads(run([str(installed / "python"), "-c", "import json, gearsym.files.paths as p; print(json.dumps("
                            "[str(p.MODELS_DIR), str(p.GENERATED_DIR)]))"], cwd=work, env=env))
    assert all(Path(w).is_relative_to(installed.parent) for w in where), where

    listed = run([str(installed / "gearsym"), "list"], cwd=work, env=env)
    assert main(["list"]) == 0
    assert listed == capsys.readouterr().out
    assert "cannot be loaded" not in listed
    assert [line.split()[0] for line in listed.splitlines()] == sorted(
        p.stem for p in (REPO_ROOT / "models").glob("*.py") if not p.stem.startswith("_"))

    lyap = json.loads(run([str(installed / "gearsym"), *LYAP], cwd=work, env=env))
    assert main(list(LYAP)) == 0
    clone = json.loads(capsys.readouterr().out)
    for key in ("exponents", "sum"):
        assert lyap[key] == pytest.approx(clone[key], rel=1e-9, abs=1e-12)
    assert lyap["final_state"] == pytest.approx(clone["final_state"], rel=1e-9, abs=1e-12)
    assert lyap["regime"] == clone["regime"]
    # the installed committed C was compiled, not C generated again into the cache
    assert not list((Path(env["GEARSYM_CACHE"]) / "code").glob("one_stage-*"))

    modes = run([str(installed / "gearsym"), "modes", "spur_pair"], cwd=work, env=env)
    assert main(["modes", "spur_pair"]) == 0
    assert_same_numbers(modes, capsys.readouterr().out)


NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


def assert_same_numbers(text: str, reference: str) -> None:
    """The same words and the same numbers (to rounding) in the same places."""
    assert NUMBER.sub("#", text) == NUMBER.sub("#", reference)
    numbers = [float(n) for n in NUMBER.findall(text)]
    assert numbers == pytest.approx([float(n) for n in NUMBER.findall(reference)], rel=1e-6, abs=1e-12)
    assert len(numbers) > 4
