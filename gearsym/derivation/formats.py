"""The output formats of a derivation, by name (what ``--format`` accepts)."""
from __future__ import annotations

from collections.abc import Callable

from ..errors import GearsymError, suggest
from .jsondoc import render_json
from .latex import render_latex
from .markdown import render_markdown
from .records import Derivation
from .text import render_text

#: name -> renderer; ``full`` selects every step (text and LaTeX; JSON and Markdown always have them)
FORMATS: dict[str, Callable[..., str]] = {
    "text": lambda d, full=False: render_text(d, full=full),
    "latex": lambda d, full=False: render_latex(d, full=full),
    "json": lambda d, full=True: render_json(d),
    "markdown": lambda d, full=True: render_markdown(d),
}


def render(derivation: Derivation, fmt: str = "text", full: bool = False) -> str:
    """The derivation in format ``fmt`` (one of :data:`FORMATS`)."""
    if fmt not in FORMATS:
        raise GearsymError(f"unknown format {fmt!r}.{suggest(fmt, FORMATS)} Formats: {', '.join(FORMATS)}")
    return FORMATS[fmt](derivation, full=full)
