"""The library cache holds code, so it is treated as ssh treats its keys: made private, not used when someone
else could write it, and a library loaded only if its bytes are those recorded when it was compiled.

Every run here is a separate ``gearsym`` process (a library loaded into the test process would stay loaded):
a cache is seeded once (under umask 000), and each test works on a copy of it at the same path, so the
summaries' paths stay valid.
"""
from __future__ import annotations

import hashlib
import json
import os
import shutil
import stat
import struct
import subprocess
import sys
from pathlib import Path

import pytest

from gearsym.codegen import compiler
from gearsym.errors import GearsymWarning
from gearsym.files.paths import REPO_ROOT

ARGS = ("--periods", "70", "--discard", "10", "--format", "json")
#: the levels of the cache path that gearsym makes (missing when it first runs)
MADE = ("made", "by", "gearsym", "cache")
NOBODY = 65534
STEPS_150 = ("--steps-per-period", "150")

PLANTED_C = r"""
#include <stdio.h>
__attribute__((constructor)) static void planted(void) {
    FILE* f = fopen("%s", "w");
    if (f) { fputs("the planted library ran\n", f); fclose(f); }
}
"""


def gearsym(cache: Path, *argv: str, umask: int | None = None) -> subprocess.CompletedProcess:
    """``gearsym *argv`` with ``cache`` (the libraries compiled -O0: these tests compile often, what they check is
    the cache and not the code's speed, and gcc -O0 takes half the time of -O1 (one_stage's C: 0.35 s against
    0.7 s); the runs they are compared with too)."""
    return _run(cache, ["-m", "gearsym.cli", *argv], umask)


def gearsym_reducing(cache: Path, *argv: str) -> tuple[subprocess.CompletedProcess, bool]:
    """``gearsym *argv`` with ``cache``, and whether the run loaded SymPy (reduced the model)."""
    script = ("import sys; from gearsym.cli import main; code = main(sys.argv[1:]); "
              "print('sympy' in sys.modules, file=sys.stderr); sys.exit(code)")
    run = _run(cache, ["-c", script, *argv])
    *said, reduced = run.stderr.splitlines() or ["?"]
    assert reduced in ("True", "False"), run.stderr
    return subprocess.CompletedProcess(run.args, run.returncode, run.stdout, "\n".join(said)), reduced == "True"


def _run(cache: Path, argv: list[str], umask: int | None = None) -> subprocess.CompletedProcess:
    env = {**os.environ, "GEARSYM_CACHE": str(cache), "PYTHONPATH": str(REPO_ROOT), "GEARSYM_CFLAGS": "-O0"}
    umasked = (lambda: os.umask(umask)) if umask is not None else None
    return subprocess.run([sys.executable, *argv], capture_output=True, text=True, env=env, cwd=REPO_ROOT,
                          timeout=300, preexec_fn=umasked)


@pytest.fixture(scope="module")
def seeded(tmp_path_factory):
    """A cache made by gearsym under umask 000 (one_stage, and duffing with its C in the cache: not the committed
    C's steps per period), kept aside; the clean runs' outputs."""
    base = tmp_path_factory.mktemp("trust")
    cache = base.joinpath(*MADE)
    clean = {}
    for name, extra in (("one_stage", ()), ("duffing", STEPS_150)):
        run = gearsym(cache, "lyap", name, *ARGS, *extra, umask=0)
        assert run.returncode == 0, run.stderr
        clean[name] = run.stdout
    modes = {p: stat.S_IMODE(os.lstat(p).st_mode) for p in [*(base.joinpath(*MADE[:k]) for k in range(1, 5)),
                                                            *cache.rglob("*")]}
    shutil.move(base / MADE[0], base / "seed")
    return base, clean, modes


@pytest.fixture
def cache(seeded):
    """A copy of the seeded cache at the path it was made at."""
    base, _, _ = seeded
    shutil.rmtree(base / MADE[0], ignore_errors=True)
    shutil.copytree(base / "seed", base / MADE[0], symlinks=True)
    return base.joinpath(*MADE)


@pytest.fixture
def clean(seeded):
    return seeded[1]


def library(cache: Path, name: str = "one_stage") -> Path:
    (lib,) = [p for p in (cache / "lib").glob(f"{name}-*.so") if "_windows" not in p.name]
    return lib


def forge_record(lib: Path, data: bytes) -> None:
    """What an attacker who can write the folder does: a record with the planted bytes' hash beside them."""
    digest = hashlib.sha256(data).hexdigest()
    old = json.loads(next(lib.parent.glob(f"{lib.name}.*.json")).read_text())
    forged = lib.with_name(f"{lib.name}.{digest[:16]}.json")
    forged.write_text(json.dumps({**old, "sha256": digest, "size": len(data)}))
    forged.chmod(0o600)


@pytest.fixture
def planted(tmp_path):
    """A shared library whose constructor writes a marker file: (its bytes, the marker)."""
    marker = tmp_path / "planted-ran"
    source = tmp_path / "planted.c"
    source.write_text(PLANTED_C % marker)
    out = tmp_path / "planted.so"
    subprocess.run(["cc", "-shared", "-fPIC", "-o", str(out), str(source)], check=True)
    return out.read_bytes(), marker


def plant(lib: Path, data: bytes) -> None:
    lib.unlink()
    lib.write_bytes(data)
    forge_record(lib, data)


def one_line_warning(stderr: str, text: str) -> str:
    lines = [line for line in stderr.splitlines() if text in line]
    assert len(lines) == 1 and lines[0].startswith("gearsym: warning: "), stderr
    assert "Traceback" not in stderr
    return lines[0]


# ------------------------------------------------------------------ made private
@pytest.mark.slow
def test_a_new_cache_is_private_at_every_level_gearsym_makes_even_under_umask_000(seeded):
    _, _, modes = seeded
    assert len(modes) > 12  # (the levels, lib/, models/, code/, libraries, records, summaries, C)
    loose = {str(p): f"{m:04o}" for p, m in modes.items() if m & 0o077}
    assert not loose
    assert [modes[p] for p in modes if p.name in MADE] == [0o700] * len(MADE)


# ------------------------------------------------------------------ planted code never runs
@pytest.mark.slow
def test_a_library_planted_in_a_cache_others_can_write_never_runs(cache, clean, planted):
    data, marker = planted
    plant(library(cache), data)  # (with a record of its bytes, and the summaries pointing at it)
    cache.chmod(0o1777)  # a shared cache, as /tmp is
    run = gearsym(cache, "lyap", "one_stage", *ARGS)
    assert run.returncode == 0, run.stderr
    assert not marker.exists()
    line = one_line_warning(run.stderr, "is not used, as someone else could put code in it")
    assert "writable by others (mode 1777)" in line
    assert run.stdout == clean["one_stage"]  # (compiled into a private temporary folder instead)


@pytest.fixture
def configured(monkeypatch):
    """Set GEARSYM_CACHE in this process (and forget the caches it went around so far)."""
    monkeypatch.setattr(compiler, "_BYPASSED", {})

    def configure(path: Path) -> Path:
        monkeypatch.setenv("GEARSYM_CACHE", str(path))
        return path

    return configure


def test_a_folder_of_the_cache_that_others_can_write_makes_gearsym_go_around_the_cache(tmp_path, configured):
    cache = configured(tmp_path / "cache")
    assert compiler.cache_dir("lib") == cache / "lib"
    (cache / "lib").chmod(0o777)
    with pytest.warns(GearsymWarning, match=rf"{cache} is not used, as someone else could put code in it: "
                                            rf"{cache / 'lib'} is writable by others \(mode 0777\)"):
        elsewhere = compiler.cache_dir("lib")
    assert cache not in elsewhere.parents and stat.S_IMODE(elsewhere.parent.stat().st_mode) == 0o700


@pytest.mark.skipif(os.geteuid() != 0, reason="giving a folder to another user needs root")
def test_a_cache_folder_of_another_user_makes_gearsym_go_around_the_cache(tmp_path, configured):
    cache = configured(tmp_path / "cache")
    (cache / "models").mkdir(parents=True, mode=0o700)
    os.chown(cache / "models", NOBODY, NOBODY)
    with pytest.warns(GearsymWarning, match=rf"{cache / 'models'} belongs to .*uid {NOBODY}\), not to you"):
        assert cache not in compiler.cache_dir("models").parents


@pytest.mark.skipif(os.geteuid() != 0, reason="a symlink of another user needs root")
def test_a_cache_reached_through_another_users_symlink_is_not_used(tmp_path, configured):
    (tmp_path / "mine").mkdir(mode=0o700)
    link = configured(tmp_path / "cache-link")
    link.symlink_to(tmp_path / "mine")
    os.lchown(link, NOBODY, NOBODY)
    with pytest.warns(GearsymWarning, match=rf"{link} is a symlink made by .*uid {NOBODY}"):
        assert tmp_path not in compiler.cache_dir().parents


def test_a_folder_above_the_cache_that_others_can_write_is_not_trusted_unless_sticky(tmp_path, configured):
    above = tmp_path / "above"
    cache = configured(above / "cache")
    above.mkdir(mode=0o777)
    above.chmod(0o1777)  # sticky, as /tmp: nobody can move the cache away
    assert compiler.cache_dir() == cache
    above.chmod(0o777)
    with pytest.warns(GearsymWarning, match=rf"{above}, a folder above it, is writable by others"):
        assert compiler.cache_dir() != cache


@pytest.mark.slow
def test_a_symlink_in_place_of_a_library_is_never_followed(cache, clean, planted, tmp_path):
    data, marker = planted
    lib = library(cache)
    elsewhere = tmp_path / "elsewhere.so"
    elsewhere.write_bytes(data)
    lib.unlink()
    lib.symlink_to(elsewhere)
    forge_record(lib, data)
    run = gearsym(cache, "lyap", "one_stage", *ARGS)
    assert run.returncode == 0, run.stderr
    assert not marker.exists()
    assert "is a symlink" in one_line_warning(run.stderr, f"{lib.name} is not used")
    assert run.stdout == clean["one_stage"]
    assert not lib.is_symlink() and elsewhere.read_bytes() == data  # (replaced, not written through)


@pytest.mark.skipif(os.geteuid() != 0, reason="giving a file to another user needs root")
@pytest.mark.slow
def test_a_library_that_belongs_to_someone_else_is_not_loaded(cache, clean, planted):
    data, marker = planted
    lib = library(cache)
    plant(lib, data)
    os.chown(lib, NOBODY, NOBODY)
    run = gearsym(cache, "lyap", "one_stage", *ARGS)
    assert run.returncode == 0, run.stderr
    assert not marker.exists()
    assert f"uid {NOBODY}" in one_line_warning(run.stderr, f"{lib.name} is not used")
    assert run.stdout == clean["one_stage"]


# ------------------------------------------------------------------ corruption
def truncate(data: bytes) -> bytes:
    return data[:len(data) // 3]


def garbage(data: bytes) -> bytes:
    return bytes((b * 7 + 13) % 256 for b in data)


def one_constant(data: bytes) -> bytes:
    """The first constant 2 pi (the C's 6.2831853071795862e+00, in the library's read-only data at -O0 as at -O1)
    made 6.3: the library loads and runs, and gives other results with exit 0."""
    two_pi = struct.pack("<d", 6.2831853071795862)
    at = data.index(two_pi)
    return data[:at] + struct.pack("<d", 6.3) + data[at + 8:]


@pytest.mark.parametrize("damage, name, extra", [(truncate, "one_stage", ()), (garbage, "duffing", STEPS_150),
                                                 (one_constant, "one_stage", ())])
@pytest.mark.slow
def test_a_damaged_library_is_found_compiled_again_from_its_c_and_gives_the_same_results(cache, clean, damage, name,
                                                                                        extra):
    """Compiled again from the C that vouches for it (one_stage's committed in generated/, duffing's in the cache
    with its record), without reducing the model again."""
    lib = library(cache, name)
    lib.write_bytes(damage(lib.read_bytes()))  # (in place: its record stays as it was)
    run, reduced = gearsym_reducing(cache, "lyap", name, *ARGS, *extra)
    assert run.returncode == 0, run.stderr
    assert "not what gearsym wrote" in one_line_warning(run.stderr, f"{lib.name} is not used")
    assert run.stdout == clean[name] and not reduced
    again = gearsym(cache, "lyap", name, *ARGS, *extra)
    assert again.returncode == 0 and "warning" not in again.stderr and again.stdout == clean[name]


@pytest.mark.slow
def test_a_changed_constant_in_the_cached_c_is_found_and_the_c_generated_again(cache, clean):
    (source,) = (cache / "code").glob("duffing-*/duffing.c")
    text = source.read_text()
    assert "6.2831853071795862e+00" in text
    source.write_text(text.replace("6.2831853071795862e+00", "6.0000000000000000e+00"))
    for path in (cache / "lib").glob("duffing-*"):  # (the C is read when the library is to be compiled)
        path.unlink()
    run = gearsym(cache, "lyap", "duffing", *ARGS, *STEPS_150)
    assert run.returncode == 0, run.stderr
    assert "not what gearsym wrote" in one_line_warning(run.stderr, "duffing.c is not used")
    assert run.stdout == clean["duffing"]
    assert "6.2831853071795862e+00" in source.read_text()


@pytest.mark.parametrize("planted, text", [("duffing_lanes.c", "GS_LANES gs_"), ("duffing.c", "GEARSYM_INLINE void")])
def test_a_changed_lanes_c_in_the_cache_is_never_compiled(cache, clean, planted, text):
    """The lanes' C is code too, and so is the model's C it includes: compiled only as gearsym wrote them;
    changed, either is refused in one line that says what to do, and no library is made from it."""
    (source,) = (cache / "code").glob(f"duffing-*/{planted}")
    source.write_text(source.read_text().replace(text, text + " /* planted */", 1))
    run = gearsym(cache, "basins", "duffing", "--grid", "x=-1:1:1", "--grid", "v=-1:1:1", *ARGS, *STEPS_150)
    assert run.returncode == 2 and run.stderr.count("gearsym: error:") == 1, run.stderr
    assert f"the C of its lanes ({source}) is not what gearsym wrote" in run.stderr and "delete" in run.stderr
    assert not list((cache / "lib").glob("duffing_lanes*"))


# ------------------------------------------------------------------ summaries checked against what they describe
def summaries(cache: Path, name: str = "one_stage") -> tuple[Path, Path]:
    """(the system summary, the build summary) of ``name`` run with ARGS."""
    files = sorted((cache / "models").glob(f"{name}-*.json"), key=lambda p: p.name.count("-"))
    system, build = files[0], next(p for p in files[1:] if json.loads(p.read_text()).get("hash"))
    return system, build


def reseal(path: Path, data: dict) -> None:
    """The edit an attacker who knows the format makes: the content hashed with the file's name again."""
    data = {k: v for k, v in data.items() if k != "seal"}
    seal = hashlib.sha256(f"{path.name}\0{json.dumps(data, sort_keys=True)}".encode()).hexdigest()
    path.write_text(json.dumps({**data, "seal": seal}, indent=1))


def swap_states(data: dict) -> dict:
    data["system"]["state_names"] = data["system"]["state_names"][::-1]
    return data


def change_default(data: dict) -> dict:
    data["system"]["parameters"]["omega"] = 1.25
    return data


@pytest.mark.parametrize("edit", [swap_states, change_default])
@pytest.mark.slow
def test_an_edited_summary_is_found_and_written_again(cache, clean, edit):
    system, _ = summaries(cache)
    system.write_text(json.dumps(edit(json.loads(system.read_text())), indent=1))
    run = gearsym(cache, "lyap", "one_stage", *ARGS)
    assert run.returncode == 0, run.stderr
    assert "edited" in one_line_warning(run.stderr, "the cached summary")
    assert run.stdout == clean["one_stage"]
    assert json.loads(system.read_text()) != edit(json.loads(system.read_text()))  # (written again)


@pytest.mark.slow
def test_an_edited_build_summary_is_said_when_a_run_asks_for_its_build_and_not_before(cache, clean):
    """The builds of a model are read together when it is opened (gearsym/codegen/kept.py read_builds); an edited one
    is said, and written again, only by the run that asks for its options."""
    system, build = summaries(cache)
    build.write_text(json.dumps({**json.loads(build.read_text()), "table_texts": []}, indent=1))  # (its seal as it was)
    other = gearsym(cache, "lyap", "one_stage", *ARGS, *STEPS_150)  # (other loops: another build)
    assert other.returncode == 0 and "the cached summary" not in other.stderr, other.stderr
    run = gearsym(cache, "lyap", "one_stage", *ARGS)
    assert run.returncode == 0, run.stderr
    assert "edited" in one_line_warning(run.stderr, "the cached summary") and str(build) in run.stderr
    assert run.stdout == clean["one_stage"]
    assert json.loads(build.read_text())["table_texts"]  # (written again)


@pytest.mark.slow
def test_summaries_edited_with_their_seal_made_again_are_checked_against_the_library(cache, clean):
    system, _ = summaries(cache)
    reseal(system, swap_states(json.loads(system.read_text())))
    run = gearsym(cache, "lyap", "one_stage", *ARGS)
    assert run.returncode == 0, run.stderr
    assert "states differ" in one_line_warning(run.stderr, "the cached summary")
    assert run.stdout == clean["one_stage"]


@pytest.mark.slow
def test_summaries_edited_with_their_seal_made_again_are_checked_against_the_c_the_library_is_compiled_from(cache,
                                                                                                           clean):
    """A damaged library is compiled again from its C only for the states and parameters the C is for."""
    system, _ = summaries(cache)
    reseal(system, swap_states(json.loads(system.read_text())))
    lib = library(cache)
    lib.write_bytes(truncate(lib.read_bytes()))
    run, reduced = gearsym_reducing(cache, "lyap", "one_stage", *ARGS)
    assert run.returncode == 0, run.stderr
    assert "not what gearsym wrote" in one_line_warning(run.stderr, f"{lib.name} is not used")
    assert run.stdout == clean["one_stage"] and reduced


@pytest.mark.slow
def test_a_summary_pointing_at_another_models_library_is_not_trusted(cache, clean):
    _, build = summaries(cache)
    _, duffing = summaries(cache, "duffing")  # (another model's build summary, library and its record: the seed's)
    other = json.loads(duffing.read_text())
    data = json.loads(build.read_text())
    reseal(build, {**data, "hash": other["hash"], "library": other["library"]})
    run = gearsym(cache, "lyap", "one_stage", *ARGS)
    assert run.returncode == 0, run.stderr
    assert "model" in one_line_warning(run.stderr, "the cached summary")
    assert run.stdout == clean["one_stage"]


@pytest.mark.slow
def test_a_summary_pointing_at_a_library_outside_the_caches_lib_folder_never_loads_it(cache, clean, planted,
                                                                                       tmp_path):
    """A library beside a record that vouches for it, in a folder of the user's own, but not the cache's lib/: a
    resealed build summary that points there is not followed (the library is compiled again in the cache)."""
    data, marker = planted
    _, build = summaries(cache)
    lib = library(cache)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir(mode=0o700)
    outside = elsewhere / lib.name
    outside.write_bytes(data)
    outside.chmod(0o600)
    forge_record(lib, data)  # (the record of the planted bytes, moved beside them)
    (forged,) = [p for p in lib.parent.glob(f"{lib.name}.*.json") if hashlib.sha256(data).hexdigest()[:16] in p.name]
    shutil.move(forged, elsewhere / forged.name)
    reseal(build, {**json.loads(build.read_text()), "library": str(outside)})
    run = gearsym(cache, "lyap", "one_stage", *ARGS)
    assert run.returncode == 0, run.stderr
    assert not marker.exists()
    assert run.stdout == clean["one_stage"]


# ------------------------------------------------------------------ a cache path that cannot be one
@pytest.mark.slow
@pytest.mark.parametrize("where", ["/dev/null", "a file", "below a file"])
def test_a_cache_path_that_is_no_folder_is_a_one_line_error_before_any_work(tmp_path, where):
    (tmp_path / "f").write_text("")
    path = {"/dev/null": "/dev/null", "a file": str(tmp_path / "f"), "below a file": str(tmp_path / "f" / "c")}[where]
    run = gearsym(Path(path), "lyap", "one_stage", *ARGS)
    assert run.returncode == 2
    assert run.stderr.startswith(f"gearsym: error: the library cache GEARSYM_CACHE={path} cannot be used: ")
    assert len(run.stderr.splitlines()) == 1 and "Traceback" not in run.stderr


@pytest.mark.slow
def test_the_library_gearsym_compile_makes_is_the_one_a_run_loads(tmp_path):
    cache = tmp_path / "cache"
    made = gearsym(cache, "compile", "duffing", "--out", str(tmp_path / "generated"))
    assert made.returncode == 0, made.stderr
    run = gearsym(cache, "lyap", "duffing", *ARGS)
    assert run.returncode == 0 and "compiling" not in run.stderr, run.stderr
    assert len(list((cache / "lib").glob("duffing-*.so"))) == 1


@pytest.mark.skipif(os.geteuid() != 0, reason="changing a folder's group needs root")
def test_a_cache_writable_by_the_users_private_group_is_theirs_by_any_other_group_it_is_not(tmp_path, configured):
    import grp
    import pwd

    me = pwd.getpwuid(os.geteuid())
    private = grp.getgrgid(me.pw_gid)
    assert private.gr_name == me.pw_name and set(private.gr_mem) <= {me.pw_name}  # (root's group here)
    cache = configured(tmp_path / "cache")
    cache.mkdir(mode=0o700)
    cache.chmod(0o770)  # umask 002, as Debian's and Fedora's users have
    assert compiler.cache_dir() == cache
    shared = next(g for g in grp.getgrall() if g.gr_gid != me.pw_gid)
    os.chown(cache, -1, shared.gr_gid)
    with pytest.warns(GearsymWarning, match=rf"{cache} is writable by others \(mode 0770\)"):
        assert compiler.cache_dir() != cache
