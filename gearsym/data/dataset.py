"""The records of one model, from one or more files: :class:`Measurements`."""
from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass, replace
from pathlib import Path

from ..errors import GearsymError
from .errors import PathLike
from .record import Record, Window


@dataclass(frozen=True, eq=False)
class Measurements:
    """Records of one model, from one or more files.

    ``defaults`` are the model's parameter values (with any settings given when loading),
    which each record's ``conditions`` override: :meth:`parameters`.
    """

    model: str
    states: tuple[str, ...]
    defaults: Mapping[str, float]
    records: tuple[Record, ...]

    def __len__(self) -> int:
        return len(self.records)

    def __iter__(self) -> Iterator[Record]:
        return iter(self.records)

    def __getitem__(self, index: int) -> Record:
        return self.records[index]

    @property
    def observed(self) -> tuple[str, ...]:
        """The channels measured in at least one record: states in the model's order, then the others."""
        seen = list(dict.fromkeys(name for r in self.records for name in r.observed))
        return tuple(s for s in self.states if s in seen) + tuple(c for c in seen if c not in self.states)

    @property
    def sources(self) -> tuple[Path, ...]:
        return tuple(dict.fromkeys(r.source for r in self.records))

    def find(self, record: str, source: PathLike | None = None) -> Record:
        """The record with this id (in ``source``, needed when several files use the id)."""
        hits = [r for r in self.records if r.record == str(record)
                and (source is None or r.source == Path(source) or r.source.name == str(source))]
        if len(hits) != 1:
            ids = ", ".join(f"{r.source.name}:{r.record}" for r in self.records)
            what = "no" if not hits else "more than one"
            raise GearsymError(f"{what} record {record!r}{'' if source is None else f' in {source}'}; records: {ids}")
        return hits[0]

    def parameters(self, record: Record) -> dict[str, float]:
        """Every parameter value of a record: the defaults, overridden by its conditions."""
        return {**self.defaults, **record.conditions}

    def windows(self) -> tuple[Window, ...]:
        """The one-forcing-period windows of every record, record after record."""
        return tuple(w for r in self.records for w in r.windows())

    def split(self, held_out: float = 0.25) -> tuple["Measurements", "Measurements"]:
        """(train, held-out): every record split by time (:meth:`Record.split`)."""
        parts = [r.split(held_out) for r in self.records]
        return (replace(self, records=tuple(p[0] for p in parts)),
                replace(self, records=tuple(p[1] for p in parts)))

