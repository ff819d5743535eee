"""What every figure shares so that nothing in it hides anything else: titles wrapped to the width they have
(never clipped at the figure's edges), legends kept off the data, and N lines told apart.

:func:`fit_texts` is called by every figure builder before it returns (and by :func:`~.save.save_figure`):
it lays the figure out, then re-wraps each title that is wider than what holds it (the figure for a
suptitle, the axes for an axes title) and lays out again. Laying out is the layout engine's work alone
(:func:`lay_out`): where every axes goes follows from the sizes of the texts around it, which need no artist
drawn; the figure is drawn once, when it is saved.
"""
from __future__ import annotations

import textwrap
from collections.abc import Iterator

#: N lines told apart: a colour each (tab10, then tab20's others) and a marker each, drawn at staggered
#: points so that lines on top of each other (degenerate exponents) still show every marker
LINE_COLORS = ("C0", "C1", "C2", "C3", "C4", "C5", "C6", "C7", "C8", "C9",
               "#aec7e8", "#ffbb78", "#98df8a", "#ff9896", "#c5b0d5", "#c49c94")
LINE_MARKERS = ("o", "s", "^", "v", "D", "P", "X", "<", ">", "*", "h", "p")


def line_style(i: int, count: int, points: int) -> dict:
    """Keyword arguments of line ``i`` of ``count``, each of ``points`` vertices: up to 4 lines a colour each
    is enough; more get a marker each too, about 12 per line at staggered vertices (line ``i`` at ``i``,
    ``i`` + step, ...), so that lines drawn on top of each other (degenerate exponents) show every marker."""
    style = {"color": LINE_COLORS[i % len(LINE_COLORS)]}
    if count > 4:
        k = max(1, points // (12 * count))
        style.update(marker=LINE_MARKERS[i % len(LINE_MARKERS)], markevery=((i % count) * k, count * k), ms=4.0,
                     mfc="none", mew=0.9)
    return style


def _titles(fig) -> Iterator[tuple[object, float]]:
    """Each title of ``fig`` with the width (pixels) it may take."""
    renderer = fig.canvas.get_renderer()
    width = fig.bbox.width
    for text in (getattr(fig, "_suptitle", None), getattr(fig, "_supxlabel", None)):
        if text is not None and text.get_text():
            yield text, 0.98 * width
    for ax in fig.axes:
        if not ax.get_visible():
            continue
        box = ax.get_window_extent(renderer)
        for title in (ax.title, ax._left_title, ax._right_title):
            if title.get_text():
                yield title, max(box.width, 0.2 * width)


def _rewrap(text, room: float, renderer) -> bool:
    """Wrap ``text`` to ``room`` pixels; True if it changed."""
    width = text.get_window_extent(renderer).width
    if width <= room:
        return False
    lines = text.get_text().split("\n")
    longest = max(lines, key=len)
    chars = max(int(len(longest) * room / width * 0.97), 12)
    wrapped = "\n".join(textwrap.fill(line, chars, break_on_hyphens=False, break_long_words=False)
                        for line in lines)
    if wrapped == text.get_text():
        return False
    text.set_text(wrapped)
    return True


def _fitted_as(fig) -> tuple:
    """What the fit of ``fig``'s titles depends on, short of laying it out: its size, its axes and every title's
    text (a builder fits its figure before it returns it, and saving it fits it again: the second fit is
    needed only where something was added or retitled in between)."""
    texts = [t.get_text() for t in (getattr(fig, "_suptitle", None), getattr(fig, "_supxlabel", None)) if t]
    texts += [t.get_text() for ax in fig.axes for t in (ax.title, ax._left_title, ax._right_title)]
    return (tuple(fig.get_size_inches()), fig.dpi, tuple(id(ax) for ax in fig.axes), tuple(texts))


def lay_out(fig) -> None:
    """Place ``fig``'s axes where its layout engine puts them when it is drawn (constrained layout: from the
    sizes of the texts around each axes), without drawing an artist: drawing a figure of many points costs its
    rendering, once, when it is saved. A figure without a layout engine keeps the positions it was given."""
    engine = fig.get_layout_engine()
    if fig.axes and engine is not None:
        try:
            engine.execute(fig)
        except ValueError:  # (as matplotlib's own draw: a layout that cannot be made leaves the positions)
            pass


def fit_texts(fig, *, again: bool = False):
    """Wrap every title of ``fig`` that is wider than what holds it, laying the figure out again until
    nothing changes; returns ``fig``, laid out with its final titles. ``again``: lay it out even if it was
    fitted as it is (what changed since may not show in its titles: :func:`~.save.save_figure` draws the
    layout made here)."""
    if not again and getattr(fig, "_gearsym_fitted", None) == _fitted_as(fig):
        return fig
    for _ in range(4):
        lay_out(fig)
        renderer = fig.canvas.get_renderer()
        if not any([_rewrap(text, room, renderer) for text, room in _titles(fig)]):
            break
    else:
        lay_out(fig)  # (the layout of the titles as they were last wrapped)
    fig._gearsym_fitted = _fitted_as(fig)
    return fig


def outside_below(ax, handles=None, labels=None, columns: int = 2, **kwargs):
    """A legend under ``ax``, outside it: it cannot cover a point."""
    given = {k: v for k, v in (("handles", handles), ("labels", labels)) if v is not None}
    return ax.legend(**given, loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=columns, frameon=False,
                     **kwargs)

