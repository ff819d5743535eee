"""Order spectra (gearsym.order_spectrum) of signals made of known lines: each labelled line's amplitude, order and
label, the FFT's amplitude at a line that falls on a bin, the noise level, the lines a short record cannot resolve,
with a mesh whose phase is not the model's time (mesh order 2.5).

A pinion of 20 teeth and a wheel of 53: over the hunting period (1060 mesh periods) every line m +- k/Z falls on a
bin of the FFT.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import gearsym

GEARS = {"pinion": 20, "wheel": 53}
MESH_ORDER = 2.5  # the mesh phase is 2.5 tau
LINES = {  # label: (order in mesh orders, amplitude, phase)
    "mesh x1": (1.0, 2.0, 0.4),
    "mesh x1 - pinion x1": (1 - 1 / 20, 0.5, -1.0),
    "mesh x2 + wheel x2": (2 + 2 / 53, 0.25, 2.0),
    "wheel x1": (1 / 53, 0.1, 0.3),
    "pinion x3": (3 / 20, 0.05, 0.0),
}


def signal(mesh_periods: float, per_period: int = 16, noise: float = 0.0, seed: int = 1):
    """(tau, x): the lines of LINES and a mean of 0.3, sampled ``per_period`` times a mesh period."""
    phase = np.arange(int(round(mesh_periods * per_period))) / per_period  # in mesh periods
    x = 0.3 + sum(a * np.cos(2 * math.pi * o * phase + p) for o, a, p in LINES.values())
    if noise:
        x = x + np.random.default_rng(seed).normal(0.0, noise, x.size)
    return 2 * math.pi * phase / MESH_ORDER, x


@pytest.fixture(scope="module")
def hunting():
    tau, x = signal(20 * 53)
    return gearsym.order_spectrum(tau, x, GEARS, mesh_order=MESH_ORDER)


def test_each_labelled_line_is_at_its_order_with_its_amplitude(hunting):
    assert hunting.length == pytest.approx(1060.0, rel=1e-12)  # mesh periods, not periods of tau
    for label, (order, amplitude, _) in LINES.items():
        line = hunting.line(label)
        assert line.order == pytest.approx(order, rel=1e-14)
        assert line.amplitude == pytest.approx(amplitude, rel=1e-9), label
    quiet = [ln for ln in hunting.lines if ln.label not in LINES]
    assert len(quiet) > 30 and max(ln.amplitude for ln in quiet) < 1e-9
    sideband = hunting.line("mesh x1 - pinion x1")
    assert (sideband.mesh, sideband.gear, sideband.shaft) == (1, "pinion", -1)
    assert hunting.line("wheel x1").mesh == 0 and hunting.line("mesh x2 + wheel x2").shaft == 2


def test_the_gears_sideband_energy_is_the_root_sum_of_its_lines(hunting):
    assert hunting.sideband_energy("pinion") == pytest.approx(math.hypot(0.5, 0.05), rel=1e-9)
    assert hunting.sideband_energy("wheel") == pytest.approx(math.hypot(0.25, 0.1), rel=1e-9)


def test_the_fft_gives_a_line_on_a_bin_its_amplitude_at_its_order(hunting):
    """Hann-windowed and amplitude-corrected: a tone on a bin reads its amplitude (to the window's 1/N)."""
    orders, amplitude = hunting.orders, hunting.amplitude
    assert orders[1] == pytest.approx(1 / 1060, rel=1e-12)  # bins 1/length apart, in mesh orders
    for label, (order, a, _) in LINES.items():
        k = int(round(order * 1060))
        assert orders[k] == pytest.approx(order, rel=1e-12)
        assert amplitude[k] == pytest.approx(a, rel=2e-3), label
    assert int(np.argmax(amplitude)) == 1060  # the mesh's own line is the tallest
    assert amplitude[0] == pytest.approx(0.0, abs=1e-6)  # the mean is removed


def test_the_noise_level_is_what_one_line_of_white_noise_reaches():
    """White noise of standard deviation s leaves a residual whose one line would reach s sqrt(2/N)."""
    tau, x = signal(20 * 53, noise=0.02)
    spectrum = gearsym.order_spectrum(tau, x, GEARS, mesh_order=MESH_ORDER)
    assert spectrum.noise == pytest.approx(0.02 * math.sqrt(2 / x.size), rel=0.05)
    assert spectrum.line("mesh x1").amplitude == pytest.approx(2.0, abs=5 * spectrum.noise)


def test_a_record_shorter_than_two_of_a_gears_revolutions_leaves_its_lines_unresolved():
    """Over 60 mesh periods the pinion (20 a revolution) turns three times, the wheel (53) not twice: every line of
    the wheel's shaft orders (its harmonics and sidebands) is left out (amplitude NaN) and said, however long its
    own cycle; the pinion's and the mesh's lines still read their amplitudes."""
    tau, x = signal(60)
    short = gearsym.order_spectrum(tau, x, GEARS, mesh_order=MESH_ORDER)
    assert short.length == pytest.approx(60.0, rel=1e-12)
    wheel = {ln.label for ln in short.lines if ln.gear == "wheel"}
    assert "wheel x1" in wheel and "mesh x2 + wheel x2" in wheel and len(wheel) == 21
    assert set(short.info["unresolved"]) == wheel
    assert all(math.isnan(short.line(label).amplitude) for label in wheel)
    assert short.line("mesh x1").amplitude == pytest.approx(2.0, rel=0.02)
    assert short.line("mesh x1 - pinion x1").amplitude == pytest.approx(0.5, rel=0.1)
    data = short.as_dict()
    assert data["length_mesh_periods"] == pytest.approx(60.0) and set(data["unresolved"]) == wheel
