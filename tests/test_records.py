"""A class made by record_class behaves as the dataclass it stands for (gearsym/records.py): the same signature,
fields, repr, equality, hash, immutability, defaults and factories, replace and asdict."""
from __future__ import annotations

import inspect
from dataclasses import FrozenInstanceError, asdict, dataclass, field, fields, replace

import pytest

from gearsym.records import record_class


def both(decorate_record, decorate_dataclass):
    """The same class body under each decorator (both named Point, so that their reprs compare)."""
    def body():
        class Point:
            x: float
            y: float = 2.0
            tags: tuple = field(default_factory=tuple)
            note: str = field(default="", repr=False, compare=False)
            norm: float = field(default=0.0, init=False)

            def __post_init__(self):
                object.__setattr__(self, "norm", abs(self.x) + abs(self.y))

        return Point

    return decorate_record(body()), decorate_dataclass(body())


@pytest.fixture
def frozen():
    return both(record_class, dataclass(frozen=True))


def test_a_record_is_built_printed_compared_and_hashed_as_its_dataclass(frozen):
    ours, theirs = frozen
    assert str(inspect.signature(ours)) == str(inspect.signature(theirs))
    undocumented = [decorate(type("Bare", (), {"__annotations__": {"x": "float"}}))
                    for decorate in (record_class, dataclass(frozen=True))]
    assert undocumented[0].__doc__ == undocumented[1].__doc__ == "Bare(x: 'float')"
    assert [f.name for f in fields(ours)] == [f.name for f in fields(theirs)]
    for args, kwargs in [((1.0,), {}), ((1.0, -3.0), {"tags": ("a",)}), ((), {"x": 0.5, "note": "n"})]:
        a, b = ours(*args, **kwargs), theirs(*args, **kwargs)
        assert repr(a) == repr(b) and asdict(a) == asdict(b) and a.norm == b.norm
        assert hash(a) == hash(b)
    assert ours(1.0, note="a") == ours(1.0, note="b") and ours(1.0) != ours(1.5)
    assert ours(1.0) != theirs(1.0)  # (another class: as two dataclasses, never equal)
    assert len({ours(1.0), ours(1.0, 2.0), ours(3.0)}) == 2
    changed = replace(ours(1.0, tags=("t",)), y=5.0)
    assert (changed.x, changed.y, changed.tags, changed.norm) == (1.0, 5.0, ("t",), 6.0)


def test_a_record_is_frozen_and_refuses_what_its_dataclass_refuses(frozen):
    ours, theirs = frozen
    for cls in (ours, theirs):
        point = cls(1.0)
        with pytest.raises(FrozenInstanceError):
            point.x = 3.0
        with pytest.raises(FrozenInstanceError):
            del point.y
        with pytest.raises(FrozenInstanceError):
            point.other = 1
        for args, kwargs in [((), {}), ((1.0, 2.0, (), "", 9), {}), ((1.0,), {"x": 2.0}), ((1.0,), {"z": 2.0}),
                             ((1.0,), {"norm": 2.0})]:
            with pytest.raises(TypeError):
                cls(*args, **kwargs)
        with pytest.raises(ValueError):
            replace(point, norm=1.0)


def test_a_record_without_equality_or_freezing_is_as_its_dataclass():
    same, _ = both(record_class(eq=False), dataclass(frozen=True, eq=False))
    point = same(1.0)
    assert point != same(1.0) and point == point and hash(point) == object.__hash__(point)
    mutable, theirs = both(record_class(frozen=False), dataclass)
    point = mutable(1.0)
    point.x = 4.0
    other = mutable(1.0)
    assert point.x == 4.0 and point != other
    other.x = 4.0
    assert point == other
    assert mutable.__hash__ is None is theirs.__hash__


def test_a_record_generates_no_code():
    """Its methods are this module's functions: none is compiled from text ('<string>'), as a dataclass's are."""
    ours, theirs = both(record_class, dataclass(frozen=True))
    methods = ("__init__", "__repr__", "__eq__", "__hash__", "__setattr__", "__delattr__")
    assert {inspect.unwrap(getattr(theirs, m)).__code__.co_filename for m in methods} == {"<string>"}
    assert "<string>" not in {inspect.unwrap(getattr(ours, m)).__code__.co_filename for m in methods}


def test_a_record_given_every_field_in_order_is_its_dataclass():
    """The shortcut of a record made in a loop (a shot, a run's inputs: every field given by position) builds what
    the dataclass builds, its __post_init__ run, frozen as ever."""
    def body():
        class Shot:
            state: float
            low: float
            high: float = 0.0

            def __post_init__(self):
                if self.low > self.high:
                    raise ValueError("low above high")

        return Shot

    ours, theirs = record_class(body()), dataclass(frozen=True)(body())
    a, b = ours(1.0, -2.0, 3.0), theirs(1.0, -2.0, 3.0)
    assert repr(a) == repr(b) and asdict(a) == asdict(b) and hash(a) == hash(b)
    assert a == ours(1.0, -2.0, high=3.0) and a != ours(-2.0, 1.0, 3.0)
    for cls in (ours, theirs):
        with pytest.raises(ValueError):
            cls(0.0, 2.0, 1.0)
    with pytest.raises(FrozenInstanceError):
        a.state = 0.0
