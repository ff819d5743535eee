"""Fig. 4 and the jumps of Fig. 3 seen as basins: what the record keeps of the basin maps and of the basin
fractions along omega, and what it says at the paper's jumps."""
from __future__ import annotations

from ..checks import json_safe
from .compute import Computed
from .plan import JUMP_TOLERANCE, PAPER_JUMPS


def _attractor(a) -> dict:
    return {"number": a.number, "fraction": a.fraction, "stderr": a.stderr, "starts": a.basin.starts,
            "period": a.period, "regime": a.regime, "description": a.description,
            "amplitude": a.amplitude.get("x"), "lambda_1": float(a.exponents[0])}


def basins_record(c: Computed) -> dict:
    """The basin maps (their attractors and shares) and the fractions along omega with their events; the
    fractions on both sides of each of the paper's jumps (``JUMP_TOLERANCE`` away: as far as a jump of ours may be
    from the paper's and still be it) and the events between."""
    maps = [{"model": model, "omega": omega, "starts": m.starts, "points": int(m.labels.shape[0]),
             "periods": m.periods, "discard": m.discard,
             "attractors": [_attractor(a) for a in m.attractors], "diverged": m.diverged.as_dict(),
             "undetermined": m.undetermined.as_dict()} for (model, omega), m in c.basins.items()]
    fractions = {}
    for model, r in c.fractions.items():
        values = list(r.values)
        rows = [{"omega": x.value, "attractor": x.id, "class": x.kind, "fraction": x.fraction, "stderr": x.stderr,
                 "period": x.period, "regime": x.regime, "amplitude": x.amplitude.get("x")} for x in r.rows]
        sides = []
        for jump in PAPER_JUMPS:  # the values on either side of the paper's jump, as far as a jump may be from it
            below = [v for v in values if v <= jump - JUMP_TOLERANCE + 1e-9]
            above = [v for v in values if v >= jump + JUMP_TOLERANCE - 1e-9]
            if not below or not above:
                continue
            lo, hi = below[-1], above[0]
            sides.append({"jump": jump, "below": lo, "above": hi,
                          "events": [e for e in r.events if lo < e["value"] <= hi],
                          "before": [x for x in rows if x["omega"] == lo and x["class"] == "attractor"],
                          "after": [x for x in rows if x["omega"] == hi and x["class"] == "attractor"]})
        fractions[model] = {"values": values, "points": int(round(len(r.record["grid"]["x"]))),
                            "rows": rows, "events": list(r.events), "jumps": sides}
    return json_safe({"maps": maps, "fractions": fractions})
