"""The order spectrum figure: amplitude against mesh orders (log scale), the labelled lines marked per gear."""
from __future__ import annotations

import textwrap
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ..analysis.orders import OrderSpectrum
from .save import pyplot, save_figure

#: marker and colour of the mesh harmonics, then of each gear's shaft orders and sidebands
STYLES = (("D", "black"), ("o", "tab:red"), ("s", "tab:blue"), ("^", "tab:green"))
#: the other meshes' harmonics, and their gears' lines
MESH_STYLES = (("P", "tab:purple"), ("X", "tab:brown"))
OTHER_STYLES = (("v", "tab:orange"), ("<", "tab:cyan"), (">", "tab:olive"), ("h", "tab:pink"))


def plot_order_spectra(spectra: Sequence[OrderSpectrum], path: str | Path, title: str = "",
                       labels: Sequence[str] | None = None, max_order: float | None = None) -> Path:
    """One panel per spectrum: the FFT (grey line, where the samples are evenly spaced) and the labelled lines
    (markers: black diamonds the mesh harmonics, one colour per gear its shaft orders and sidebands), the three
    strongest sidebands named."""
    plt = pyplot()
    fig, axes = plt.subplots(len(spectra), 1, figsize=(9, 3.2 * len(spectra) + 0.8), squeeze=False)
    for i, (ax, s) in enumerate(zip(axes[:, 0], spectra)):
        top = max_order or (max((ln.order for ln in s.lines), default=1.0) + 0.5)
        if s.orders.size:
            keep = s.orders <= top
            ax.semilogy(s.orders[keep], np.maximum(s.amplitude[keep], 1e-12), color="0.6", lw=0.7,
                        label="spectrum (Hann window)")
        others = {g: z for _, gears in s.meshes.values() for g, z in gears.items() if g not in s.gears}
        styles = {None: STYLES[0], **{g: STYLES[1 + k % 3] for k, g in enumerate(s.gears)},
                  **{m: MESH_STYLES[k % len(MESH_STYLES)] for k, m in enumerate(s.meshes)},
                  **{g: OTHER_STYLES[k % len(OTHER_STYLES)] for k, g in enumerate(others)}}
        for gear, (marker, colour) in styles.items():
            chosen = [ln for ln in s.lines if ln.gear == gear and np.isfinite(ln.amplitude) and ln.amplitude > 0]
            if not chosen:
                continue
            teeth = {**s.gears, **others}
            name = ("mesh harmonics" if gear is None else
                    f"mesh {gear}: its harmonics (at {s.meshes[gear][0]:.4g} orders)" if gear in s.meshes else
                    f"{gear} ({teeth[gear]} teeth): shaft orders, sidebands")
            ax.semilogy([ln.order for ln in chosen], [ln.amplitude for ln in chosen], marker, color=colour, ms=5,
                        ls="none", label=name)
        strongest = sorted((ln for ln in s.lines if ln.gear is not None and np.isfinite(ln.amplitude)),
                           key=lambda ln: -ln.amplitude)[:3]
        named: list[float] = []
        for ln in strongest:  # (one label where lines crowd)
            if all(abs(ln.order - o) > 0.04 * top for o in named):
                ax.annotate(ln.label, (ln.order, ln.amplitude), textcoords="offset points", xytext=(4, 6), fontsize=7)
                named.append(ln.order)
        ax.set_xlim(0, top)
        ax.set_ylabel(f"amplitude of {s.channel}" + (f" ({s.unit})" if s.unit else ""))
        ax.set_title(textwrap.fill((labels[i] if labels else "") or s.title, 110), fontsize=8)
        ax.legend(fontsize=7, loc="upper right")
        ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel("frequency in orders of the mesh (mesh frequency = 1; a gear of Z teeth turns at 1/Z)")
    if title:
        fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    return save_figure(fig, path, dpi=100)
