"""The findings of a sweep (jumps, hysteresis) as text a person reads: each one names the line it lies on
(direction and the values of the other swept parameters); a long list is summarised and the full one
left to the JSON record."""
from __future__ import annotations

import textwrap
from collections import Counter
from pathlib import Path

from .result import SweepResult

#: more jumps (or hysteresis intervals) than this are summarised instead of listed
LISTED = 10
#: how many of the largest a summary shows
LARGEST = 5


def findings_lines(result: SweepResult, record: str | Path, findings: dict | None = None) -> list[str]:
    """Lines for the jumps and hysteresis intervals of ``result``; ``record`` is where the full list is."""
    findings = result.findings() if findings is None else findings
    first, others = result.axes[0].name, [a.name for a in result.axes[1:]]
    units = result.units  # (a sweep in physical units: rpm, um)

    def unit(column: str) -> str:
        return f" {units[column]}" if column in units else ""

    def where(item: dict) -> str:
        return ", ".join([*([item["direction"]] if "direction" in item else []),
                          *(f"{n}={item[n]:g}{unit(n)}" for n in others)])

    def jump(j: dict) -> str:
        return (f"jump in A_{j['coordinate']} ({where(j)}): {first} {j['from']:g} -> {j['to']:g}{unit(first)}, "
                f"A {j['A_before']:.4g} -> {j['A_after']:.4g}{unit('A_' + j['coordinate'])}")

    def hysteresis(h: dict) -> str:
        on = f" ({where(h)})" if others else ""
        return (f"hysteresis in A_{h['coordinate']}{on}: up and down differ for {first} in "
                f"[{h['from']:g}, {h['to']:g}]{unit(first)}")

    jumps, intervals = findings["jumps"], findings["hysteresis"]
    lines = _listed_or_summary(jumps, jump, where, "jumps", "largest (|change in A|)",
                               lambda j: abs(j["A_after"] - j["A_before"]), record, "jumps")
    lines += _listed_or_summary(intervals, hysteresis, where, "hysteresis intervals", f"widest (in {first})",
                                lambda h: h["to"] - h["from"], record, "hysteresis")
    return lines


def _listed_or_summary(items: list[dict], line, where, what: str, largest: str, size, record, key: str) -> list[str]:
    if len(items) <= LISTED:
        return [line(item) for item in items]
    per_line = Counter(where(item) for item in items)
    per_coordinate = Counter(f"A_{item['coordinate']}" for item in items)
    counts = "; ".join(f"{k or 'the sweep'}: {n}" for k, n in per_line.items())
    top = sorted(items, key=size, reverse=True)[:LARGEST]
    return [
        f"{len(items)} {what} ({', '.join(f'{k} {n}' for k, n in per_coordinate.items())}) "
        f"on {len(per_line)} line{'s' if len(per_line) != 1 else ''}:",
        textwrap.fill(counts, width=100, initial_indent="  per line: ", subsequent_indent="    "),
        f"  the {len(top)} {largest}:",
        *(f"    {line(item)}" for item in top),
        f"  every one, with the values of all swept parameters: {record} (\"{key}\")",
    ]
