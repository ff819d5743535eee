"""``gearsym stiffness``: its text and JSON, its refusals (one line, exit status 2), and the committed figure."""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from gearsym.cli import main

REPO = Path(__file__).resolve().parents[1]
NASA = ["stiffness", "--teeth", "28,28", "--module", "3.175 mm", "--face-width", "6.35 mm", "--pressure-angle",
        "20 deg"]
#: how docs/figures/stiffness-nasa-rig.{json,png} are made (docs/geometry.md shows the same command)
FIGURE = REPO / "docs" / "figures" / "stiffness-nasa-rig"


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_json_has_the_issues_keys_in_si(capsys):
    code, out, err = run(capsys, *NASA, "--bore", "20 mm", "--format", "json")
    assert code == 0 and "warning" not in err  # (a bore inside Sainsot's range: nothing to warn about)
    data = json.loads(out)
    for key in ("contact_ratio", "mean", "min", "max", "phase", "stiffness", "iso6336"):
        assert key in data, key
    assert len(data["phase"]) == len(data["stiffness"]) == 720
    assert data["phase"][0] == 0.0 and data["phase"][-1] < 2 * math.pi
    assert data["min"] <= min(data["stiffness"]) <= data["mean"] <= max(data["stiffness"]) <= data["max"]
    iso = data["iso6336"]
    assert iso["unit"] == "N/(mm um)" and iso["c_gamma_beta"] == pytest.approx(0.85 * iso["c_gamma_alpha"])
    assert iso["mean_N_per_m"] == pytest.approx(iso["c_gamma_alpha"] * 6.35 * 1e6)
    assert data["contact_ratio"] == pytest.approx(1.6380042, rel=1e-7, abs=0)
    assert data["units"]["mean"] == "N/m"
    assert data["gears"][0]["base_diameter"] == pytest.approx(0.0889 * math.cos(math.radians(20)), rel=1e-14, abs=0)


def test_text_answers_in_the_users_units(capsys):
    code, out, err = run(capsys, *NASA[:4], "0.125 in", *NASA[5:], "--helix-angle", "10 deg", "--slices", "8")
    assert code == 0
    lines = out.splitlines()
    assert lines[0] == ("28/28 teeth, module 0.125 in, pressure angle 20 deg, face width 6.35 mm, "
                        "helix angle 10 deg")
    overlap = 6.35 * math.sin(math.radians(10)) / (math.pi * 3.175)  # b sin(beta) / (pi m_n)
    assert lines[1].startswith("contact ratio: transverse") and f"overlap {overlap:.6g}" in lines[1]
    assert "centre distance 3.55" in lines[2] and " in," in lines[2]  # lengths in the module's unit
    assert any(line.startswith("mesh stiffness (8 slices): mean ") and line.endswith("N/m") for line in lines)
    assert any(line.startswith("ISO 6336-1 method B, N/(mm um): c'_th ") for line in lines)
    assert lines.index("curve over one mesh period:") < len(lines) - 30
    assert "solid" in err  # Sainsot's formula needs a bore: the assumption is said


@pytest.mark.parametrize("argv, words", [
    (["--module", "3"], "no unit"),
    (["--module", "3 s"], "not a length"),
    (["--module", "3 parsec/"], "quantity"),
    (["--pressure-angle", "20 mm"], "not an angle"),
    (["--teeth", "28"], "2 values"),
    (["--teeth", "28,x"], "whole number"),
    (["--teeth", "3,28"], "at least 6"),
    (["--bore", "90 mm"], "root circle"),
    (["--material", "206 GPa"], "2 values"),
    (["--material", "206 mm,0.3"], "not a pressure"),
    (["--material", "206 GPa,0.7"], "Poisson"),
    (["--slices", "0"], "at least 1"),
    (["--profile-shift", "0.2"], "2 values"),
    (["--centre-distance", "80 mm"], "jam"),
    (["--rack", "1,1.25"], "3 values"),
    (["--plot", "out.txt"], "must end in"),
])
def test_bad_input_is_one_line_and_exit_status_2(capsys, tmp_path, argv, words):
    args = dict(zip(NASA[1::2], NASA[2::2]))
    args.update(zip(argv[::2], argv[1::2]))
    flat = ["stiffness"] + [x for kv in args.items() for x in kv]
    if "--plot" in args:
        flat[flat.index("--plot") + 1] = str(tmp_path / args["--plot"])
    code, out, err = run(capsys, *flat)
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and err.startswith("gearsym: error:") and words in err, err


def _numbers_close(a, b, path="") -> None:
    if isinstance(a, dict):
        assert a.keys() == b.keys(), path
        for k in a:
            _numbers_close(a[k], b[k], f"{path}.{k}")
    elif isinstance(a, list):
        assert len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b)):
            _numbers_close(x, y, f"{path}[{i}]")
    elif isinstance(a, float):
        assert a == pytest.approx(b, rel=1e-9, abs=1e-12), path
    else:
        assert a == b, path


def test_the_committed_figure_and_data_regenerate(capsys, tmp_path):
    """docs/figures/stiffness-nasa-rig.{json,png}: `gearsym stiffness --teeth 28,28 --module "3.175 mm"
    --face-width "6.35 mm" --pressure-angle "20 deg" --format json --plot docs/figures/stiffness-nasa-rig.png
    > docs/figures/stiffness-nasa-rig.json`."""
    code, out, _ = run(capsys, *NASA, "--format", "json", "--plot", str(tmp_path / "k.png"))
    assert code == 0
    _numbers_close(json.loads(out), json.loads(FIGURE.with_suffix(".json").read_text()))
    from matplotlib.image import imread

    new, committed = imread(tmp_path / "k.png"), imread(FIGURE.with_suffix(".png"))
    # pixels, not bytes (another matplotlib may encode the same picture differently): faint differences of
    # antialiasing pass, a line or a word that moved does not
    assert new.shape == committed.shape, "docs/figures/stiffness-nasa-rig.png differs in size"
    moved = (np.abs(new - committed).max(axis=-1) > 0.25).mean()
    assert np.abs(new - committed).mean() < 2e-3 and moved < 2e-4, \
        f"docs/figures/stiffness-nasa-rig.png differs ({moved:.2%} of its pixels): rerun the command in this docstring"
    committed_numbers_are_the_formulas(json.loads(FIGURE.with_suffix(".json").read_text()))


def committed_numbers_are_the_formulas(data: dict) -> None:
    """The committed JSON checked against what does not come from regenerating it: ISO 21771's contact ratio and
    ISO 6336-1's q', c'_th, c', c_gamma_alpha typed here for the 28/28 pair (x = 0, rack h_fP = 1.25 m), and its
    mean, minimum and maximum against its own curve."""
    m, z, alpha = 3.175e-3, 28, math.radians(20)
    d, db, da = z * m, z * m * math.cos(alpha), z * m + 2 * m
    a = d  # (two equal gears, no shift: the reference centre distance)
    eps = (math.sqrt(da ** 2 - db ** 2) - a * math.sin(alpha)) / (math.pi * m * math.cos(alpha))
    assert data["contact_ratio"] == pytest.approx(eps, rel=1e-12)
    iso = data["iso6336"]
    q = 0.04723 + 0.15551 / z + 0.25791 / z
    c_th, C_B = 1 / q, 1 + 0.5 * (1.2 - 1.25)
    assert (iso["q_prime"], iso["c_th"], iso["C_B"]) == pytest.approx((q, c_th, C_B), rel=1e-12)
    assert iso["c_prime"] == pytest.approx(c_th * 0.8 * C_B, rel=1e-12)
    assert iso["c_gamma_alpha"] == pytest.approx(c_th * 0.8 * C_B * (0.75 * eps + 0.25), rel=1e-12)
    assert iso["mean_N_per_m"] == pytest.approx(iso["c_gamma_alpha"] * 6.35e-3 * 1e9, rel=1e-12)
    k = np.array(data["stiffness"])
    assert np.diff(data["phase"]) == pytest.approx(np.full(len(k) - 1, 2 * math.pi / len(k)), rel=1e-9)
    assert data["mean"] == pytest.approx(k.mean(), rel=1e-3)  # (the samples straddle the contact's jumps)
    assert data["min"] == pytest.approx(k.min(), rel=1e-3) and data["max"] == pytest.approx(k.max(), rel=1e-9)


CRACKED = REPO / "docs" / "figures" / "stiffness-cracked-tian"
TIAN = ("stiffness", "--teeth", "19,48", "--module", "3.2 mm", "--face-width", "16 mm", "--pressure-angle", "20 deg", "--material",
        "206.8 GPa,0.3")


def test_the_committed_crack_figure_and_data_regenerate(capsys, tmp_path):
    """docs/figures/stiffness-cracked-tian.{json,png}, the command docs/geometry.md gives: Tian's 19/48 pair with a 3 mm
    crack at 70 deg on a pinion tooth, the mesh stiffness while it passes and the loss against depth."""
    code, out, _ = run(capsys, *TIAN, "--crack", "3 mm,70 deg", "--cracked-gear", "1", "--format", "json", "--plot",
                       str(tmp_path / "k.png"))
    assert code == 0
    made, committed = json.loads(out), json.loads(CRACKED.with_suffix(".json").read_text())
    _numbers_close(made, committed)
    crack = made["crack"]
    assert 0.10 < crack["mean_loss"] < 0.25 and crack["mean_losses"] == sorted(crack["mean_losses"])
    assert min(np.subtract(crack["healthy"], crack["cracked"])) > -1e-6  # the crack only softens the mesh
    from matplotlib.image import imread

    new, old = imread(tmp_path / "k.png"), imread(CRACKED.with_suffix(".png"))
    assert new.shape == old.shape, "docs/figures/stiffness-cracked-tian.png differs in size"
    moved = (np.abs(new - old).max(axis=-1) > 0.25).mean()
    assert np.abs(new - old).mean() < 2e-3 and moved < 2e-4, \
        f"docs/figures/stiffness-cracked-tian.png differs ({moved:.2%} of its pixels): rerun docs/geometry.md's command"


def test_a_crack_through_the_tooth_is_refused_before_any_work(capsys):
    code, _, err = run(capsys, *TIAN, "--crack", "9 mm,80 deg", "--cracked-gear", "1")
    assert code == 2 and "reaches the other flank of the tooth" in err and "Traceback" not in err


# --------------------------------------------------------------------------- the basic rack
HIGH = NASA[:-1] + ["25 deg"]


def test_a_25_degree_pair_is_cut_by_the_largest_rounding_that_fits_and_says_so(capsys):
    """ISO 53's 0.38 does not fit a 25 deg rack: the default is the full-round tip, computed, and said."""
    code, out, err = run(capsys, *HIGH, "--format", "json")
    assert code == 0, err
    rack = json.loads(out)["rack"]
    alpha, rho, hf = math.radians(25), rack["tip_rounding"], rack["dedendum"]
    # the tool's tip, in modules: the line y = 0 from -w to w, flanks down and outwards at alpha from the vertical.
    # A full-round tip's circle is centred on the axis, touches the tip line and both flanks
    w = math.pi / 4 - hf * math.tan(alpha)
    corner, down = np.array([w, 0.0]), np.array([math.sin(alpha), -math.cos(alpha)])
    centre = np.array([0.0, -rho])
    to_flank = (centre - corner) - np.dot(centre - corner, down) * down
    assert np.linalg.norm(to_flank) == pytest.approx(rho, rel=1e-12)
    assert 0.3178 < rho < 0.3179 and rack["addendum"] == 1.0
    code, out, err = run(capsys, *HIGH)
    assert code == 0
    assert out.splitlines()[0].endswith("pressure angle 25 deg, face width 6.35 mm, rack 1/1.25/0.318 (full-round tip)")
    assert ("basic rack (both gears): addendum 1, dedendum 1.25, tip rounding 0.318 (in modules): a full-round tip, the "
            "largest rounding that fits this 25 deg rack; ISO 53's 0.38 does not fit it") in out.splitlines()
    code, same, _ = run(capsys, *HIGH, "--rack", f"1,1.25,{rho!r}")
    assert code == 0 and same.splitlines()[1:] == out.splitlines()[1:]  # the default is that rack, given


def test_a_20_degree_pair_keeps_iso_53_profile_a(capsys):
    code, out, _ = run(capsys, *NASA)
    assert code == 0
    assert "basic rack (both gears): ISO 53 profile A: addendum 1, dedendum 1.25, tip rounding 0.38 (in modules)" \
        in out.splitlines() and "rack" not in out.splitlines()[0]


@pytest.mark.parametrize("angle, rack, words", [
    ("25 deg", "1,1.25,0.38", "fillet radius coefficient 0.38 must lie in 0-0.318 on a 25 deg rack of dedendum 1.25"),
    ("33 deg", None, "dedendum coefficient 1.25 is too deep for a 33 deg rack"),
])
def test_a_rack_that_does_not_fit_its_pressure_angle_is_refused_in_one_line(capsys, angle, rack, words):
    code, out, err = run(capsys, *NASA[:-1], angle, *(["--rack", rack] if rack else []))
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and err.startswith("gearsym: error:") and words in err, err
