"""The mesh stiffness of a gear pair over one mesh period, its contact zones, its mean and ISO 6336-1's."""
from __future__ import annotations

import math
import textwrap
from pathlib import Path

import numpy as np

from .save import pyplot, save_figure

#: shading of the zones by the number of pairs of teeth in contact
_ZONE_COLOURS = {1: "0.88", 2: "#cfe3f5", 3: "#d9f0d3", 4: "#f5e6cf"}


def plot_mesh_stiffness(result, path: str | Path | None = None, title: str | None = None):
    """``result`` (a :class:`~gearsym.geometry.MeshStiffness`) against the mesh phase: the curve (solid), its mean
    (dotted), ISO 6336-1's mean mesh stiffness c_gamma_alpha b (dashed), the zones shaded by the number of pairs of
    teeth in contact; a right-hand axis per unit face width in N/(mm um). ``title``: the pair in the user's units."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(8.0, 4.6), constrained_layout=True)
    section = " (mid-face section)" if result.overlap_ratio > 0 else ""
    shaded = set()
    for zone in result.zones:
        label = None
        if zone.pairs not in shaded:
            shaded.add(zone.pairs)
            label = f"{zone.pairs} pair{'s' if zone.pairs != 1 else ''} of teeth in contact{section}"
        ax.axvspan(zone.start, zone.end, color=_ZONE_COLOURS.get(zone.pairs, "0.95"), zorder=0, label=label)
    # the curve drawn through its jumps: the samples plus both sides of each jump
    jumps = result._curve.jumps()
    phase = np.sort(np.concatenate([result.phase, jumps[1:-1] - 1e-9, jumps[1:-1] + 1e-9, [2.0 * math.pi - 1e-9]]))
    ax.plot(phase, result.at(phase), color="k", lw=1.4, label="potential-energy method")
    ax.axhline(result.mean, color="k", ls=":", lw=1.2, label=f"its mean {result.mean:.4g} N/m")
    iso = result.iso6336.mean_stiffness
    ax.axhline(iso, color="C3", ls="--", lw=1.2, label=f"ISO 6336-1 mean c$_{{\\gamma\\alpha}}$ b = {iso:.4g} N/m")
    ax.set_xlim(0.0, 2.0 * math.pi)
    ax.set_xticks([0.0, 0.5 * math.pi, math.pi, 1.5 * math.pi, 2.0 * math.pi],
                  ["0", "π/2", "π", "3π/2", "2π"])
    ax.set_xlabel("mesh phase φ [rad]: one mesh period; φ = 0 when a pair of teeth enters contact")
    ax.set_ylabel("mesh stiffness k [N/m]")
    top = max(result.max, iso)
    ax.set_ylim(0.0, 1.3 * top)
    width_mm = result.pair.face_width * 1e3
    right = ax.secondary_yaxis("right", functions=(lambda k: k / (width_mm * 1e6), lambda c: c * width_mm * 1e6))
    right.set_ylabel("per unit face width [N/(mm µm)]")
    ax.legend(fontsize=7.5, loc="upper right", ncol=2)
    eps = f"ε_α = {result.contact_ratio:.4g}" + (f", ε_β = {result.overlap_ratio:.4g}, {result.slices} slices"
                                                if result.overlap_ratio > 0 else "")
    heading = "\n".join(textwrap.wrap(title or result.pair.describe(), 100))
    ax.set_title(f"{heading}\n{_bodies(result.pair)}\nmesh stiffness over one mesh period ({eps})", fontsize=9)
    if path is not None:
        save_figure(fig, path, dpi=120)
    return fig


def _bodies(pair) -> str:
    """'E 206 GPa, nu 0.3; gear bodies solid / bored' (what the stiffness rests on besides the geometry)."""
    m1, m2 = pair.gear1.material, pair.gear2.material
    material = (f"E {m1.E / 1e9:.4g} GPa, ν {m1.nu:.3g}" if m1 == m2 else
                f"E {m1.E / 1e9:.4g}/{m2.E / 1e9:.4g} GPa, ν {m1.nu:.3g}/{m2.nu:.3g}")
    bodies = " / ".join("solid" if g.bore_diameter == 0 else "bored" for g in (pair.gear1, pair.gear2))
    return f"{material}; gear bodies {bodies} (Sainsot et al. 2004)"


def plot_cracked_mesh(pair, gear: int, crack, cracked: dict, path: str | Path | None = None, title: str | None = None):
    """A root crack's cost: left, the mesh stiffness while the cracked tooth passes (its pair in contact from phase 0
    to 2 pi eps), healthy (black) and cracked (red), the zones shaded; right, the crack's mean loss over the path of
    contact against its depth at its angle, the depth drawn marked and where the crack reaches the centre line.
    ``cracked``: what ``gearsym stiffness --crack`` computes (the CLI's ``_cracked``)."""
    plt = pyplot()
    fig, (ax, right) = plt.subplots(1, 2, figsize=(11.0, 4.6), constrained_layout=True,
                                    gridspec_kw={"width_ratios": [1.6, 1.0]})
    e = pair.contact_ratio
    periods = np.asarray(cracked["phase"]) / (2 * math.pi)
    for start in range(-1, math.ceil(e) + 1):  # double contact: where a pair enters, for eps - 1 mesh periods
        ax.axvspan(start, start + e - 1, color=_ZONE_COLOURS[2], zorder=0,
                   label="2 pairs of teeth in contact" if start == -1 else None)
    ax.axvspan(0, e, ymax=0.04, color="C3", alpha=0.5, zorder=1, label="the cracked tooth's pair in contact")
    healthy, broken = np.asarray(cracked["healthy"]), np.asarray(cracked["cracked"])
    ax.plot(periods, healthy, color="k", lw=1.4, label="healthy")
    ax.plot(periods, broken, color="C3", lw=1.4,
            label=f"cracked: {cracked['depth'] * 1e3:.3g} mm at {math.degrees(cracked['angle']):.3g}° "
                  f"(mean loss of its pair {100 * cracked['mean_loss']:.3g} %)")
    ax.set_xlim(periods[0], periods[-1])
    ax.set_ylim(0.0, 1.3 * healthy.max())
    ax.set_xlabel("mesh periods since the cracked tooth's pair came into contact (φ / 2π)")
    ax.set_ylabel("mesh stiffness k [N/m]")
    ax.legend(fontsize=7.5, loc="upper right", ncol=2)
    ax.set_title(f"mesh stiffness while the cracked tooth (gear {gear}, {(pair.gear1, pair.gear2)[gear - 1].teeth} "
                 f"teeth) passes (ε_α = {e:.4g})", fontsize=9)
    depths = np.asarray(cracked["depths"]) * 1e3
    right.plot(depths, 100 * np.asarray(cracked["mean_losses"]), color="C3", lw=1.4,
               label="mean over the path of contact")
    right.axvline(cracked["depth"] * 1e3, color="C3", ls=":", lw=1.0, label="the crack drawn left")
    crossing = cracked["centre_line_depth"] * 1e3
    if crossing < depths[-1]:
        right.axvline(crossing, color="0.4", ls="--", lw=1.0, label="reaches the tooth's centre line")
    right.set_xlabel(f"crack depth [mm] at {math.degrees(cracked['angle']):.3g}° to the centre line")
    right.set_ylabel("stiffness of the cracked pair lost [%]")
    right.set_xlim(0, depths[-1])
    right.set_ylim(0, None)
    right.legend(fontsize=7.5, loc="upper left")
    right.set_title(f"loss against depth (from the {cracked['origin'].replace('_', ' ')})", fontsize=9)
    heading = "\n".join(textwrap.wrap(title or pair.describe(), 130))
    fig.suptitle(f"{heading}\n{_bodies(pair)}", fontsize=9)
    if path is not None:
        save_figure(fig, path, dpi=110)
    return fig
