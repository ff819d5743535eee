"""Writing a figure: one place for the PNG settings every figure shares."""
from __future__ import annotations

from pathlib import Path

from .layout import fit_texts


def pyplot():
    """matplotlib's pyplot on the Agg backend (no display needed), imported when a figure is drawn: a command
    that draws none never loads matplotlib."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_figure(fig, path: str | Path, dpi: int) -> Path:
    """Write ``fig`` to ``path`` (folders made as needed) and close it, its titles wrapped to fit
    (:func:`~.layout.fit_texts`). No 'Software' entry, so the bytes do not depend on the matplotlib version:
    committed figures are compared as files."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fit_texts(fig)
    fig.savefig(path, dpi=dpi, metadata={"Software": None})
    pyplot().close(fig)
    return path
