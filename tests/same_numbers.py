"""Committed outputs compared as numbers, not bytes (``gearsym.reproduce.rounding`` says how): texts, listings, JSON
records, and CSV files cell by cell."""
from __future__ import annotations

import csv
import io
import re

import numpy as np

from gearsym.reproduce.rounding import NUMBER, differences, numbers_agree, record_differences

__all__ = ["NUMBER", "csv_differences", "differences", "json_differences", "measured_differences", "numbers_agree",
           "wrong_models_held"]
json_differences = record_differences


def csv_differences(made: str, committed: str, rel: float = 1e-9, absolute: float = 0.0) -> list[str]:
    """Where two CSV texts differ: headers and text cells exactly, numbers within ``rel`` (or ``absolute``)."""
    rows_made, rows_committed = (list(csv.reader(io.StringIO(t))) for t in (made, committed))
    if len(rows_made) != len(rows_committed):
        return [f"{len(rows_made)} rows made, {len(rows_committed)} committed"]
    found = []
    for number, (m, c) in enumerate(zip(rows_made, rows_committed), 1):
        if len(m) != len(c):
            found.append(f"row {number}: {len(m)} cells made, {len(c)} committed")
            continue
        for x, y in zip(m, c):
            if x == y:
                continue
            try:
                a, b = float(x), float(y)
            except ValueError:
                found.append(f"row {number}: {x!r} made, {y!r} committed")
                continue
            if not abs(a - b) <= max(absolute, rel * max(abs(a), abs(b))):
                found.append(f"row {number}: {x} made, {y} committed")
        if len(found) > 20:
            break
    return found


def measured_differences(made: str, committed: str, states: tuple[str, ...], *, trajectory: float = 1e-4,
                         attractor: bool = False) -> list[str]:
    """Where two tables of ``gearsym simulate`` differ by more than rounding can make them differ: every column but
    ``states`` (times, records, operating conditions) as numbers to 1e-12; each state of each record within
    ``trajectory`` of the record's range. A record on a chaotic attractor grows a difference of rounding (another
    machine's FMA contraction or SIMD width) as e^(lambda t): with ``attractor``, a record that has left the committed
    trajectory must still be on its attractor, which is what holds on any machine: the same spread (standard
    deviation within 5 %), mean (within 0.1 of the spread) and extremes (within 10 % of the range)."""
    (header_made, *rows_made), (header, *rows) = (list(csv.reader(io.StringIO(t))) for t in (made, committed))
    if header_made != header or len(rows_made) != len(rows):
        return [f"columns {header_made} and {len(rows_made)} rows made, {header} and {len(rows)} committed"]
    fixed = [i for i, name in enumerate(header) if name not in states]
    found = csv_differences("\n".join(",".join(r[i] for i in fixed) for r in rows_made),
                            "\n".join(",".join(r[i] for i in fixed) for r in rows), rel=1e-12)
    a, b = (np.array([[float(r[header.index(s)]) for s in states] for r in t]) for t in (rows_made, rows))
    record = np.array([r[header.index("record")] for r in rows])
    for number in dict.fromkeys(record):
        for column, name in enumerate(states):
            x, y = a[record == number, column], b[record == number, column]
            span = np.ptp(y)
            if np.max(np.abs(x - y)) <= trajectory * span:
                continue
            same_attractor = (abs(x.std() - y.std()) <= 0.05 * y.std() and abs(x.mean() - y.mean()) <= 0.1 * y.std()
                              and max(abs(x.min() - y.min()), abs(x.max() - y.max())) <= 0.1 * span)
            if not (attractor and same_attractor):
                found.append(f"record {number}, {name}: {np.max(np.abs(x - y)):.3g} from the committed one "
                             f"(range {span:.3g}); mean {x.mean():.4g} made, {y.mean():.4g} committed; "
                             f"spread {x.std():.4g} made, {y.std():.4g} committed")
    return found


ESTIMATE = re.compile(r"(\w+) = (-?[\d.e+-]+) ± ([\d.e+-]+)")


def wrong_models_held(report: str) -> tuple[str, dict]:
    """The report with what it says of the wrong models (the model as declared and each rejected candidate) written
    as "wrong model", and what of them holds on any machine. A wrong model's fit and its one-period-ahead prediction
    grow a difference of rounding: the rig's model as declared fits zeta = 0.05831 ± 0.0029 and predicts 0.3514 (the
    committed report: the window libraries at -O1 -fno-tree-pta, whose FMA contractions differ) where the same C at
    -O3 fits 0.05451 ± 0.0029 (another minimum of a cost the missing effect has made rough) and predicts 0.3696, and
    without FMA contraction 0.05831 and 0.3499; under another BLAS kernel mesh_stiffness_harmonic_2 predicts 0.382
    for 0.3205. What holds: the candidates, each one's note, each held-out error far above the chosen one's, its
    estimates within the uncertainties stated, the screening's refitted candidates and the orders that stand out."""
    lines, held = [], {"errors": {}, "estimates": {}, "notes": {}, "screened": None, "orders": None}
    for line in report.split("\n"):
        cells = line.split(" | ")
        if line.startswith("| ") and len(cells) == 5 and NUMBER.fullmatch(cells[1].strip()):  # a candidate's row
            name = cells[0][2:]
            if "**chosen**" in line:
                held["chosen"] = float(cells[1])
            else:
                held["errors"][name] = float(cells[1])
                held["notes"][name] = cells[4]
                held["estimates"].update({f"{name}: {e[0]}": (float(e[1]), float(e[2]))
                                          for e in ESTIMATE.findall(cells[3])})
                line = f"| {name} | wrong model |"
        elif line.startswith("- Added:"):
            line = re.sub(r"Held-out error \S+ → (\S+) \(\S+ lower\)", r"Held-out error (wrong model) → \1", line)
        elif line.startswith("Screened out as declared"):
            gains = re.findall(r"(\w+) (\d[\d.e+-]*)(?:;|\.$)", line.split(": ", 1)[1])
            held["screened"] = sorted(name for name, gain in gains if float(gain) >= 0.02)
            line = "Screened out as declared: wrong model"
        elif "Orders that stand out as declared:" in line:
            orders = re.search(r"as declared: ([^;]*);", line).group(1)
            held["orders"] = sorted(orders.split(", "))
            line = line.replace(orders, "wrong model")
        elif line.startswith("| as declared |"):
            line = "| as declared | wrong model |"
        elif line.startswith("| ") and len(cells) == 3 and "±" in cells[1]:  # an estimate: as declared, after
            held["estimates"][f"before: {cells[0][2:]}"] = tuple(map(float, cells[1].split(" ± ")))
            line = " | ".join([cells[0], "wrong model", cells[2]])
        lines.append(line)
    return "\n".join(lines), held
