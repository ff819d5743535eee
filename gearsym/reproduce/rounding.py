"""Results compared as another machine would round them: another CPU (SIMD width, BLAS kernel, FMA contraction)
rounds the same computation otherwise, and a number printed to its last digit may then print one unit away.

Two texts are the same if they are word for word the same outside their numbers, and each pair of numbers
agrees: integers exactly (counts, orders, indices), decimals to one unit in the last digit printed of the less
precise of the two (``1.307`` and ``1.308``, ``4.4e-06`` and ``4.5e-06``: a value near a rounding boundary
prints either way), or within ``rel`` of each other where a caller gives one. Two JSON records are the same if
they have the same keys, lengths, integers and texts (as above), and floats within ``rel`` (or ``absolute``).
``gearsym reproduce`` keeps a committed record that its new one equals so (the tree stays clean on another
machine); the tests compare committed pages and listings so.
"""
from __future__ import annotations

import math
import re

NUMBER = re.compile(r"(?<![\w.])[-+−]?(?:\d+\.\d+|\.\d+|\d+)(?:[eE][-+]?\d+)?(?!\w|\.\w)")


def _value(text: str) -> float:
    return float(text.replace("−", "-"))


def _last_digit(text: str) -> float | None:
    """One unit in the last digit ``text`` prints (None for an integer)."""
    mantissa, _, exponent = text.lower().partition("e")
    if "." not in mantissa and not exponent:
        return None
    decimals = len(mantissa.partition(".")[2])
    return 10.0 ** (int(exponent or 0) - decimals)


def numbers_agree(a: str, b: str, rel: float = 0.0) -> bool:
    """Whether two printed numbers are the same result (see the module's docstring)."""
    x, y = _value(a), _value(b)
    units = [u for u in (_last_digit(a), _last_digit(b)) if u is not None]
    if not units:
        return x == y or abs(x - y) <= rel * max(abs(x), abs(y))
    if math.isnan(x) or math.isnan(y):
        return math.isnan(x) and math.isnan(y)
    return abs(x - y) <= max(units) * (1 + 1e-9) + rel * max(abs(x), abs(y))


def differences(made: str, committed: str, rel: float = 0.0) -> list[str]:
    """Where ``made`` and ``committed`` differ, as lines of both (empty: the same)."""
    found = []
    made_lines, committed_lines = made.splitlines(), committed.splitlines()
    if len(made_lines) != len(committed_lines):
        found.append(f"{len(made_lines)} lines made, {len(committed_lines)} committed")
    for number, (m, c) in enumerate(zip(made_lines, committed_lines), 1):
        if m == c:
            continue
        same_words = NUMBER.split(m) == NUMBER.split(c)
        pairs = list(zip(NUMBER.findall(m), NUMBER.findall(c)))
        if not same_words or len(NUMBER.findall(m)) != len(NUMBER.findall(c)) or not all(
                numbers_agree(x, y, rel) for x, y in pairs):
            found.append(f"line {number}:\n  made:      {m}\n  committed: {c}")
    return found


def record_differences(made, committed, rel: float = 1e-9, absolute: float = 0.0, path: str = "") -> list[str]:
    """Where two JSON values differ: the same keys, lengths, strings (compared as texts with numbers, with ``rel``),
    integers and booleans exactly, floats within ``rel`` (or ``absolute``)."""
    if isinstance(committed, dict):
        if not isinstance(made, dict) or made.keys() != committed.keys():
            return [f"{path}: keys {sorted(made) if isinstance(made, dict) else made!r} made, {sorted(committed)} committed"]
        return [d for k in committed for d in record_differences(made[k], committed[k], rel, absolute, f"{path}.{k}")]
    if isinstance(committed, list):
        if not isinstance(made, list) or len(made) != len(committed):
            return [f"{path}: {made!r} made, {committed!r} committed"]
        return [d for i, (m, c) in enumerate(zip(made, committed))
                for d in record_differences(m, c, rel, absolute, f"{path}[{i}]")]
    if isinstance(committed, float) and isinstance(made, (int, float)) and not isinstance(made, bool):
        if made == committed or abs(made - committed) <= max(absolute, rel * max(abs(made), abs(committed))):
            return []
        return [f"{path}: {made!r} made, {committed!r} committed"]
    if isinstance(committed, str) and isinstance(made, str):
        return [f"{path}: {d}" for d in differences(made, committed, rel)]
    return [] if made == committed and type(made) is type(committed) else [f"{path}: {made!r} made, {committed!r} committed"]
