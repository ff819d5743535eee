"""Records: dataclasses whose methods are functions written once, here, rather than code generated per class.

``dataclasses.dataclass`` writes each class's ``__init__``, ``__repr__``, ``__eq__``, ``__hash__`` and (frozen)
``__setattr__`` and ``__delattr__`` as source text and compiles it when the class is defined: about a millisecond
a class, and the 32 classes a command on a cached model defines were a tenth of its start-up (issue 39).
:func:`record_class` makes the same class -- a dataclass (``dataclasses.fields``, ``replace`` and ``asdict`` work on
it), frozen unless told otherwise, compared and hashed by its fields, printed and called as the dataclass is --
with the functions below, which read the class's fields when they run. The modules a cached run imports
declare their classes with it (tests/test_startup_cache.py), but for codegen/loops.py, whose text is part of
every generated library's hash; the rest keep ``@dataclass``.
"""
from __future__ import annotations

import dataclasses
import inspect
from dataclasses import MISSING, FrozenInstanceError
from reprlib import recursive_repr


def record_class(cls=None, /, *, eq: bool = True, frozen: bool = True):
    """``@dataclass(frozen=frozen, eq=eq)`` without generated code: ``@record_class``, ``@record_class(eq=False)``."""
    if cls is None:
        return lambda c: record_class(c, eq=eq, frozen=frozen)
    undocumented = not cls.__dict__.get("__doc__")
    if undocumented:  # (else the dataclass writes one from the signature it finds before ours: object's)
        cls.__doc__ = cls.__name__
    cls = dataclasses.dataclass(cls, init=False, repr=False, eq=False)
    every = dataclasses.fields(cls)
    arguments = tuple(f for f in every if f.init)
    names = tuple(f.name for f in arguments)
    # (name, default, factory) of each field, in order: what __init__ sets
    setting = tuple((f.name, f.default, f.default_factory, f.init) for f in every)
    post_init = getattr(cls, "__post_init__", None) is not None
    # every field given in order, none outside __init__ to default, none a descriptor of the class: the values go
    # straight into the instance's dict
    every_given_in_order = len(arguments) == len(every) and not any(
        hasattr(getattr(cls, n, None), "__set__") for n in names) and "__slots__" not in cls.__dict__

    def __init__(self, *args, **kwargs):
        if not kwargs and len(args) == len(names) and every_given_in_order:  # (a record made in a loop: a shot)
            self.__dict__.update(zip(names, args))
            if post_init:
                self.__post_init__()
            return
        if len(args) > len(names):
            raise TypeError(f"{cls.__qualname__}.__init__() takes {len(names) + 1} positional arguments but "
                            f"{len(args) + 1} were given")
        given = dict(zip(names, args))
        for name in kwargs:
            if name in given or name not in names:
                why = "got multiple values for argument" if name in given else "got an unexpected keyword argument"
                raise TypeError(f"{cls.__qualname__}.__init__() {why} {name!r}")
        given.update(kwargs)
        for name, default, factory, init in setting:
            if init and name in given:
                value = given[name]
            elif default is not MISSING:
                value = default
            elif factory is not MISSING:
                value = factory()
            else:
                raise TypeError(f"{cls.__qualname__}.__init__() missing 1 required argument: {name!r}")
            object.__setattr__(self, name, value)
        if post_init:
            self.__post_init__()

    __init__.__qualname__ = f"{cls.__qualname__}.__init__"
    cls.__init__ = __init__
    cls.__signature__ = inspect.Signature([inspect.Parameter(f.name, inspect.Parameter.POSITIONAL_OR_KEYWORD,
                                                             default=_default(f), annotation=f.type)
                                           for f in arguments], return_annotation=None)
    if undocumented:  # (as the dataclass's: its name and signature)
        cls.__doc__ = cls.__name__ + str(cls.__signature__).replace(" -> None", "")
    cls.__repr__ = _repr_of(tuple(f.name for f in every if f.repr))
    if eq:
        cls.__eq__ = _eq_of(tuple(f.name for f in every if f.compare))
        cls.__hash__ = (_hash_of(tuple(f.name for f in every if (f.compare if f.hash is None else f.hash)))
                        if frozen else None)
    if frozen:
        cls.__setattr__, cls.__delattr__ = _frozen(cls, frozenset(f.name for f in every))
    return cls


def _default(f: dataclasses.Field):
    """A field's default as the dataclass's ``__init__`` signature shows it."""
    if f.default is not MISSING:
        return f.default
    return _FACTORY if f.default_factory is not MISSING else inspect.Parameter.empty


class _Factory:
    """The default a signature shows for a field made by its factory, as the dataclass's does."""

    def __repr__(self):
        return "<factory>"


_FACTORY = _Factory()


def _repr_of(names: tuple[str, ...]):
    @recursive_repr()
    def __repr__(self):
        return f"{type(self).__qualname__}({', '.join(f'{n}={getattr(self, n)!r}' for n in names)})"

    return __repr__


def _eq_of(names: tuple[str, ...]):
    def __eq__(self, other):
        if other.__class__ is not self.__class__:
            return NotImplemented
        return tuple(getattr(self, n) for n in names) == tuple(getattr(other, n) for n in names)

    return __eq__


def _hash_of(names: tuple[str, ...]):
    def __hash__(self):
        return hash(tuple(getattr(self, n) for n in names))

    return __hash__


def _frozen(cls: type, names: frozenset[str]):
    """The frozen dataclass's ``__setattr__`` and ``__delattr__``: a field, or anything of the class itself, is not
    assigned or deleted."""
    def __setattr__(self, name, value):
        if type(self) is cls or name in names:
            raise FrozenInstanceError(f"cannot assign to field {name!r}")
        super(cls, self).__setattr__(name, value)

    def __delattr__(self, name):
        if type(self) is cls or name in names:
            raise FrozenInstanceError(f"cannot delete field {name!r}")
        super(cls, self).__delattr__(name)

    return __setattr__, __delattr__
