"""A unit text pint has read once is read again without pint (gearsym/units.py UnitMeaning, gearsym/files/memo.py):
what it means is kept in the user's private cache, sealed, and trusted no more than the cache's other records."""
from __future__ import annotations

import json
import os
import subprocess
import sys
import warnings

import pytest

from gearsym import units
from gearsym.errors import GearsymWarning
from gearsym.files import sealed
from gearsym.files.memo import keep
from gearsym.files.paths import REPO_ROOT

#: what the docs and the shipped models write (an alias, a product, a power, a prefix, a plain number)
TEXTS = ("9100 rpm", "2e8 N/m", "2.1e-3 kg*m^2", "50 um", "3000 rev/min", "71.8 N m", "1e-3 kg/(m*s)", "4 min^-1",
         "100 Hz", "1.5", "3 deg")
#: what a run shows and converts its results with
SHOWN = ("revolutions_per_minute", "micrometer", "newton * meter")
CONVERSIONS = (("rad/s", "rpm"), ("rad/s", "Hz"), ("m", "um"))

SCRIPT = f"""
import json, sys
from gearsym import units
print(json.dumps({{
    "measures": [repr(units.measure(t, "x")) for t in {TEXTS!r}],
    "shown": [[units.symbol(u), units.si_factor(u), units.unit_dims(u)] for u in {SHOWN!r}],
    "conversions": [units.conversion_factor(a, b) for a, b in {CONVERSIONS!r}],
    "pint": "pint" in sys.modules,
}}))
"""


def answers(cache) -> dict:
    """What a user's process answers for the texts (a process of its own, with ``cache`` as its cache)."""
    run = subprocess.run([sys.executable, "-c", SCRIPT], capture_output=True, text=True, cwd=REPO_ROOT, timeout=120,
                         env={**os.environ, "PYTHONPATH": str(REPO_ROOT), "GEARSYM_CACHE": str(cache)})
    assert run.returncode == 0, run.stderr
    return {**json.loads(run.stdout), "stderr": run.stderr}


def pints_answers() -> dict:
    """The same answers, asked of pint itself in this process (what a kept meaning must reproduce to the bit)."""
    registry = units.registry()
    measures = []
    for text in TEXTS:
        number, _, unit_text = text.partition(" ")
        q = registry.Quantity(float(number), units.ALIASES.get(unit_text.replace(" ", ""), unit_text) or None)
        dims = dict(q.dimensionality)
        name = "" if str(q.units) == "dimensionless" else str(q.units)
        measures.append(repr(units.Measure(float(q.to_base_units().magnitude),
                                           tuple(float(dims.get(d, 0)) for d in units.BASE), float(number), name)))
    shown = [[f"{registry.Unit(u):~P}", float(registry.Quantity(1.0, u).to_base_units().magnitude),
              list(float(dict(registry.Unit(u).dimensionality).get(d, 0)) for d in units.BASE)] for u in SHOWN]
    conversions = [float(registry.Quantity(1.0, a).to(b).magnitude) for a, b in CONVERSIONS]
    return {"measures": measures, "shown": shown, "conversions": conversions}


def test_a_second_process_reads_the_units_the_first_met_without_pint_and_means_what_pint_says(tmp_path):
    first, second = answers(tmp_path / "cache"), answers(tmp_path / "cache")
    assert first["pint"] and not second["pint"], second["stderr"]
    expected = pints_answers()
    for answered in (first, second):
        assert {k: answered[k] for k in expected} == expected


@pytest.fixture
def cache(tmp_path, monkeypatch):
    """A cache of this test's own, and this process's kept meanings forgotten (as in a new process)."""
    monkeypatch.setenv("GEARSYM_CACHE", str(tmp_path / "cache"))
    monkeypatch.setattr(units, "_KNOWN", {})
    return tmp_path / "cache"


def kept(cache, text: str):
    """The record kept for ``text`` (its path and content)."""
    [path] = [p for p in (cache / "units").glob("*.json") if json.loads(p.read_text())["question"] == text]
    return path, json.loads(path.read_text())


def test_an_edited_meaning_is_not_trusted_but_said_and_written_again(cache, monkeypatch):
    right = units.measure("9100 rpm", "speed")
    path, record = kept(cache, "rpm")
    record["answer"]["factor"] *= 2  # (twice the speed: a planted answer, its seal left as it was)
    path.write_text(json.dumps(record))
    monkeypatch.setattr(units, "_KNOWN", {})
    with pytest.warns(GearsymWarning, match=rf"kept meaning of a unit {path} is not used: its content is not what"):
        assert units.measure("9100 rpm", "speed") == right
    assert kept(cache, "rpm")[1]["answer"]["factor"] == units.registry().Quantity(1.0, "rpm").to_base_units().magnitude


@pytest.mark.parametrize("plant", ["writable by others", "a symlink"])
def test_a_meaning_someone_else_could_have_written_is_not_read(cache, monkeypatch, tmp_path, plant):
    right = units.measure("50 um", "eta")
    path, record = kept(cache, "um")
    record["answer"]["factor"] = 1e-3  # (a sealed answer as gearsym would write it, saying um is a mm)
    record.pop("seal")
    keep("units", "um", record["depends"], record["answer"])
    if plant == "writable by others":
        path.chmod(0o666)
    else:
        planted = tmp_path / "planted.json"
        path.rename(planted)
        path.symlink_to(planted)
    monkeypatch.setattr(units, "_KNOWN", {})
    with pytest.warns(GearsymWarning, match=rf"kept meaning of a unit {path} is not used: .*"
                                            rf"{'writable by others' if plant != 'a symlink' else 'is a symlink'}"):
        assert units.measure("50 um", "eta") == right
    assert units.symbol("micrometer") == "µm" and units.si_factor("micrometer") == 1e-6


def test_a_cache_someone_else_could_write_keeps_no_meaning_and_says_nothing(cache):
    cache.mkdir(mode=0o777)
    cache.chmod(0o777)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert units.measure("2e8 N/m", "kZ").si == 2e8
    assert not (cache / "units").exists()


def test_an_edited_meaning_of_a_unit_not_asked_for_is_said_once_not_in_every_process(cache, monkeypatch):
    units.measure("50 um", "eta")
    path, record = kept(cache, "um")
    record["answer"]["factor"] = 1e-3  # (its seal left as it was)
    path.write_text(json.dumps(record))
    monkeypatch.setattr(units, "_KNOWN", {})
    with pytest.warns(GearsymWarning, match=rf"kept meaning of a unit {path} is not used"):
        assert units.measure("9100 rpm", "speed").si == pytest.approx(9100 * 2 * 3.141592653589793 / 60)
    monkeypatch.setattr(units, "_KNOWN", {})  # (a later process, which does not ask for um either)
    monkeypatch.setattr(sealed, "_DISTRUSTED", set())
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert units.measure("9100 rpm", "speed").si == pytest.approx(9100 * 2 * 3.141592653589793 / 60)
