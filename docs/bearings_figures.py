"""The figures of docs/bearings.md: the projection of a mesh's centre motions on its line of action, and the natural
modes of Lin & Parker's translational planetary set for 3, 4 and 5 planets with their three kinds.

    python docs/bearings_figures.py        # from the repository's root: writes docs/figures/bearings-*.png
"""
from __future__ import annotations

import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from gearsym.analysis.modes import drivetrain_modes  # noqa: E402
from gearsym.registry import load_model  # noqa: E402
from gearsym.scales.si_values import si_values  # noqa: E402

FIGURES = Path(__file__).parent / "figures"
KINDS = {"rotational": ("#1f77b4", "o"), "translational": ("#d62728", "s"), "planet": ("#2ca02c", "^")}


def line_of_action(path: Path) -> None:
    """Two external gears (pinion counterclockwise, the wheel to its right), their base circles, the line of action
    of the flank the pinion's positive rotation closes (tilted by the pressure angle from the pitch circles'
    common tangent), and the centres' displacements d_a, d_b with their projections on it."""
    alpha, r1, r2 = math.radians(20.0), 1.0, 1.4
    c1, c2 = np.array([0.0, 0.0]), np.array([(r1 + r2), 0.0])
    n = np.array([math.sin(alpha), math.cos(alpha)])  # 90 deg - alpha from the line of centres
    fig, ax = plt.subplots(figsize=(7.5, 5.2))
    for c, r, name in ((c1, r1, "gear a (pinion)"), (c2, r2, "gear b (wheel)")):
        ax.add_patch(plt.Circle(c, r, fill=False, ls="-", lw=1.2, color="0.35"))
        ax.add_patch(plt.Circle(c, r * math.cos(alpha), fill=False, ls=":", lw=1.0, color="0.5"))
        ax.plot(*c, "k+", ms=9)
        ax.annotate(name, c + np.array([0, -r - 0.25]), ha="center", fontsize=9)
    pitch = c1 + np.array([r1, 0.0])
    t1 = c1 + r1 * math.cos(alpha) * np.array([math.cos(alpha), -math.sin(alpha)])
    t2 = c2 - r2 * math.cos(alpha) * np.array([math.cos(alpha), -math.sin(alpha)])
    ax.plot(*zip(t1 - 1.3 * n, t2 + 1.1 * n), color="C1", lw=2.2, label="line of action, direction n (drive flank)")
    ax.annotate("", xy=pitch + 1.0 * n, xytext=pitch, arrowprops=dict(arrowstyle="->", color="C1", lw=2.0))
    ax.text(*(pitch + 1.05 * n + np.array([0.05, 0.0])), "n", color="C1", fontsize=12)
    ax.plot(*zip(c1, c2), color="0.6", lw=0.8, ls="--", label="line of centres")
    ax.annotate("", xy=pitch + 0.9 * np.array([0, 1]), xytext=pitch, arrowprops=dict(arrowstyle="-", color="0.6",
                                                                                   ls=":"))
    ax.text(pitch[0] + 0.1, pitch[1] + 0.75, "α", fontsize=13, color="C1")
    ax.annotate("", xy=c1 + np.array([-0.45, 0.55]), xytext=c1 + np.array([-0.65, 0.1]),
                arrowprops=dict(arrowstyle="->", connectionstyle="arc3,rad=-0.4", color="k"))
    ax.text(c1[0] - 0.95, c1[1] + 0.55, "ψ_a", fontsize=11)
    for c, d, name, color, side in ((c1, np.array([0.55, 0.15]), "d_a", "C0", 1),
                                    (c2, np.array([-0.15, -0.75]), "d_b", "C2", -1)):
        ax.annotate("", xy=c + d, xytext=c, arrowprops=dict(arrowstyle="->", color=color, lw=2.0))
        ax.text(*(c + d + np.array([0.05, -0.12 * side])), name, color=color, fontsize=11)
        foot = c + (d @ n) * n
        ax.plot(*zip(c + d, foot), color=color, lw=0.9, ls=":")
        ax.annotate("", xy=foot, xytext=c, arrowprops=dict(arrowstyle="->", color=color, lw=1.2, ls="--"))
        ax.text(*(foot + np.array([-0.55, 0.02 * side])), f"(n·{name}) n", color=color, fontsize=10)
    ax.set_title("A mesh of gears on bearings: δ = r_a ψ_a − r_b ψ_b + n·(d_a − d_b)\n"
                 "(pressure angle α = 20°; dotted circles: base circles; solid: pitch circles)", fontsize=10)
    ax.set_aspect("equal")
    ax.set_xlim(-1.6, 4.2)
    ax.set_ylim(-2.1, 2.2)
    ax.legend(loc="upper right", fontsize=8)
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def planetary_modes(path: Path) -> None:
    """Every natural frequency of the translational planetary set for N = 3, 4, 5 (Lin & Parker's example
    system as models/planetary_translational.py declares it), marked by kind, with its multiplicity."""
    fig, ax = plt.subplots(figsize=(8.5, 4.6))
    seen = set()
    for row, planets in enumerate((3, 4, 5)):
        model = load_model("planetary_translational", {"planets": planets})
        modes = drivetrain_modes(model, si_values(model, {}))
        shown = set()
        for m in modes.modes:
            if m.kind == "rigid" or round(m.frequency, 3) in shown:
                continue
            shown.add(round(m.frequency, 3))
            color, marker = KINDS[m.kind]
            ax.plot(m.frequency / 1e3, planets, marker, color=color, ms=9,
                    label=m.kind if m.kind not in seen else None)
            seen.add(m.kind)
            if m.multiplicity > 1:
                ax.annotate(f"×{m.multiplicity}", (m.frequency / 1e3, planets), textcoords="offset points",
                            xytext=(0, 8), ha="center", fontsize=7, color=color)
    ax.set_yticks([3, 4, 5])
    ax.set_ylim(2.5, 5.6)
    ax.set_xlabel("natural frequency (kHz)")
    ax.set_ylabel("planets N")
    ax.set_title("Lin & Parker's translational planetary set (models/planetary_translational.py): its natural modes\n"
                 "rotational ×1, translational ×2, planet ×(N − 3); the rigid-body mode at 0 Hz not drawn", fontsize=10)
    ax.legend(loc="lower right", fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    FIGURES.mkdir(exist_ok=True)
    line_of_action(FIGURES / "bearings-line-of-action.png")
    planetary_modes(FIGURES / "bearings-planetary-modes.png")
    print("wrote docs/figures/bearings-line-of-action.png, docs/figures/bearings-planetary-modes.png")
