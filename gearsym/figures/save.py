"""Writing a figure: one place for the PNG settings every figure shares."""
from __future__ import annotations

import io
from pathlib import Path

from ..files.atomic import write_atomically
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
    committed figures are compared as files. Written whole or not at all (:func:`~gearsym.files.write_atomically`:
    a full disk leaves no half a figure)."""
    path = Path(path)
    fit_texts(fig)
    image = io.BytesIO()
    try:
        fig.savefig(image, format=path.suffix.lstrip(".").lower() or None, dpi=dpi, metadata={"Software": None})
    finally:
        pyplot().close(fig)
    return write_atomically(path, image.getvalue())
