"""Writing a figure: one place for the PNG settings every figure shares."""
from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from ..files.atomic import write_atomically
from .layout import fit_texts


def pyplot():
    """matplotlib's pyplot on the Agg backend (no display needed), imported when a figure is drawn: a command
    that draws none never loads matplotlib."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


#: a new picture is the one on disk if its pixels differ by at most this on average (0..1 per channel) and at most
#: this share of them by more than a quarter: antialiasing of a line moved by rounding passes, a moved marker, line
#: or word does not
SAME_MEAN, SAME_MOVED = 2e-3, 2e-4


def save_figure(fig, path: str | Path, dpi: int, keep_same: bool = False) -> Path:
    """Write ``fig`` to ``path`` (folders made as needed) and close it, its titles wrapped to fit
    (:func:`~.layout.fit_texts`): laid out at ``dpi``, then drawn once, as laid out. No 'Software' entry, so the
    bytes do not depend on the matplotlib version: committed figures are compared as files. Written whole or not
    at all (:func:`~gearsym.files.atomic.write_atomically`: a full disk leaves no half a figure). ``keep_same``: a
    file already there that shows the same picture (:func:`same_picture`) is left as it is (a committed figure
    redrawn on another machine, whose rounding moved a line by a fraction of a pixel)."""
    path = Path(path)
    image = _drawn(fig, path, dpi)
    if keep_same and path.is_file() and same_picture(image, path):
        return path
    return write_atomically(path, image.getvalue())


def figure_bytes(fig, path: str | Path, dpi: int) -> bytes:
    """The bytes :func:`save_figure` writes to ``path`` for ``fig`` (closed): for a caller that writes them with
    its other files."""
    return _drawn(fig, Path(path), dpi).getvalue()


def _drawn(fig, path: Path, dpi: int) -> io.BytesIO:
    """``fig`` drawn in the format of ``path``'s suffix and closed, its titles wrapped to fit at ``dpi``; the
    picture is read from its start."""
    fig.set_dpi(dpi)  # (laid out at the resolution it is written at: the layout made here is the one drawn)
    fit_texts(fig, again=True)
    engine = fig.get_layout_engine()
    image = io.BytesIO()
    try:
        if engine is not None:  # drawn as laid out above, not laid out once more
            without_layout(fig)
        fig.savefig(image, format=path.suffix.lstrip(".").lower() or None, dpi=dpi, metadata={"Software": None})
    finally:
        if engine is not None:
            fig.set_layout_engine(engine)
        pyplot().close(fig)
    image.seek(0)  # (the picture is read back from its start, without a copy of its bytes)
    return image


def without_layout(fig) -> None:
    """Take ``fig``'s layout engine away (put it back with ``fig.set_layout_engine(engine)``): no engine at all,
    not matplotlib's 'none', whose stand-in engine has ``savefig`` draw the whole figure once without rendering
    before it draws it for the file (about a third of a save's drawing, for a layout that is not made again)."""
    import matplotlib

    with matplotlib.rc_context({"figure.autolayout": False, "figure.constrained_layout.use": False}):
        fig.set_layout_engine(None)  # (None is no engine unless these ask for one)


def finish(fig, path: str | Path | None, dpi: int):
    """A figure builder's last step: ``fig`` written to ``path`` at ``dpi`` (:func:`save_figure`: its titles are
    fitted there, at the resolution it is written at) if a path is given, else its titles fitted for the caller
    (:func:`~.layout.fit_texts`); returns ``fig``."""
    if path is not None:
        save_figure(fig, path, dpi)
    else:
        fit_texts(fig)
    return fig


def same_picture(a, b: str | Path) -> bool:
    """Whether two PNG images (files or file objects) show the same picture (their pixels, not their bytes; see
    ``SAME_MEAN``)."""
    from matplotlib.image import imread

    try:
        x, y = imread(a, format="png"), imread(b, format="png")
    except (OSError, ValueError, SyntaxError):
        return False
    if x.shape != y.shape:
        return False
    difference = np.abs(x.astype(float) - y.astype(float))
    moved = (difference.max(axis=-1) if difference.ndim == 3 else difference) > 0.25
    return float(difference.mean()) <= SAME_MEAN and float(moved.mean()) <= SAME_MOVED
