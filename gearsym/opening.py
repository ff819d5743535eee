"""A model opened for a run: from what a run asks of its model (:class:`ModelRequest`: the model's name or file,
its values, the run's :class:`~gearsym.options.Integration`) to what it runs on: the model's scaling (None without
physical values) and its compiled model, from the start-up cache (:mod:`gearsym.cached`) when it has them, else
the model loaded, reduced and compiled here, and kept in the cache.

:func:`open_model` reads the cache's slot once; what the run asks for is made on first use and kept
(:class:`OpenModel`): a command asks for the scaling, checks its request against it, and only then has the model
compiled (seconds), so that bad input is refused before the long work. The loading and compiling verbs are the
face's (``gearsym.load``, ``gearsym.scaling``, ``gearsym.compile_model``, which import SymPy and the code generator
on first use): a run on a cached model imports neither SymPy nor pint.
"""
from __future__ import annotations

import itertools
from collections.abc import Callable, Mapping
from dataclasses import field, replace
from functools import cached_property

import gearsym  # the face: its verbs load on first use, so a cached model's run never loads the generator

from .records import record_class
from . import stability  # (its modules load on first use: the linearisation's only when it is derived)
from .cached import Making, cache_slot, load_linearisation, load_static_recipe
from .options import Integration
from .physical.point import CachedScaling


@record_class
class ModelRequest:
    """What a run asks of its model, read once from the caller: ``model`` (a name or the path of a model file),
    ``settings`` (its values as ``gearsym.load`` takes them: numbers, quantities, a stiffness formula in tau, a
    length scale, ``teeth``; a formula's numbers are checked when the model is built, so a cached model's run
    never loads SymPy), the run's ``options``, whether to say what is compiled (``verbose``), and how an error
    names one of the settings (``given_as``: ``"--set"`` names ``--set k``)."""

    model: str
    settings: Mapping[str, object] = field(default_factory=dict)
    options: Integration = field(default_factory=Integration)
    verbose: bool = False
    given_as: str = ""


def checked_formulas(settings: Mapping[str, object], given_as: str = "") -> dict:
    """``settings``, after each formula among them is built (SymPy) to check its numbers: 1/0, log(0) or exp(1000)
    are refused, naming the setting as it was given (``f"{given_as} {name}"``), before the model is loaded."""
    for name, value in settings.items():
        if is_formula(name, value):
            gearsym.parse_formula(value, f"{given_as} {name}".strip())
    return dict(settings)


def is_formula(name: str, value) -> bool:
    """Whether a setting is a formula (text that is not a length scale's name: quantities and numbers were read
    into what they are when they were given)."""
    return isinstance(value, str) and name != "length_scale"


class OpenModel:
    """A model opened for a run (:func:`open_model`): what the start-up cache holds for it (:attr:`slot`, read
    once), and what a run asks for, made on first use and kept: :attr:`scaling`, :attr:`system`,
    :meth:`compiled`, and for a stability chart :meth:`linearised` and :meth:`static_recipe`."""

    def __init__(self, request: ModelRequest):
        self.request = request
        self.slot = cache_slot(request.model, request.settings)

    @cached_property
    def checked_settings(self) -> dict:
        """The request's settings, each formula's numbers checked (SymPy): what loading the model takes."""
        return checked_formulas(self.request.settings, self.request.given_as)

    @cached_property
    def scaling(self):
        """The model's scaling, or None without physical values: from the cache's numbers when it has them (a
        :class:`~gearsym.physical.point.CachedScaling`, whose full scaling is made only if asked for), else the
        full one (the model loaded and reduced: seconds)."""
        if self.slot.physical is False:
            return None
        if self.slot.units is not None:
            return CachedScaling(self.slot.units, lambda: self.full_scaling)
        return self.full_scaling

    @cached_property
    def full_scaling(self):
        """The model's :class:`~gearsym.scales.map.Scaling` (the model loaded and reduced), or None."""
        if not gearsym.is_physical(self.request.model, **self.checked_settings):
            return None
        physical = dict(self.checked_settings)
        length_scale = physical.pop("length_scale", None)
        return gearsym.scaling(self.request.model, length_scale, **physical)  # (a stiffness formula too)

    @cached_property
    def system(self):
        """The model's first-order system (loaded and reduced: seconds)."""
        return gearsym.load(self.request.model, **self.checked_settings)

    @cached_property
    def summary(self):
        """What a run checks its request against (names, parameters, cycles): the cache's summary of the system
        when it has one (:class:`~gearsym.codegen.system_summary.SystemSummary`, which loads the full system only
        if asked for its symbolic part), else :attr:`system`."""
        summary = self.slot.summary(lambda: self.system)
        return self.system if summary is None else summary

    def compiled(self, options: Integration | None = None, *, over: Mapping | None = None,
                 before: Callable[[object], object] | None = None):
        """The compiled model, with ``options`` (default: the request's): from the start-up cache when it has it,
        else the model loaded, ``before(system)`` (the run's checks of its request against the loaded system, made
        before the compiler's seconds), compiled and kept in the cache
        (:meth:`~gearsym.cached.CacheSlot.compiled_model`).
        ``over``: the engine's axes (name -> values) a sweep or a continuation runs over; the step is chosen for its
        fastest point (their ends decide; an integrator asked is kept), so that the model is compiled once."""
        return self.slot.compiled_model(options or self.request.options, _ends(over) if over else [], Making(
            load_system=lambda: self.system,
            choose_over=lambda options, ends: gearsym.chosen_integration(options, self.system, ends),
            compile_system=lambda system, options: gearsym.compile_model(system, options,
                                                                         verbose=self.request.verbose),
            kept_units=lambda: None if self.scaling is None else self.scaling.point_units(),
            before=before))

    def linearised(self, before: Callable[[object], object] | None = None):
        """The compiled linearisation about the model's static state (a chart's): from the cache, else the model
        loaded, ``before(system)`` (the chart's checks against it), linearised and compiled."""
        request = self.request
        return load_linearisation(request.model, request.settings, request.options, verbose=request.verbose,
                                  derive=lambda: self._linearised(before))

    def _linearised(self, before: Callable[[object], object] | None):
        system = self.system
        physical = gearsym.is_physical(self.request.model, **self.checked_settings)
        if before is not None:
            before(system)
        lin = stability.compile_linearisation(system, self.request.options, verbose=self.request.verbose)
        return replace(lin, physical=physical)

    def static_recipe(self):
        """The static problem of the model (the start of a chart about its periodic orbits): from the cache, else
        derived from the loaded model."""
        return load_static_recipe(self.request.model, self.request.settings,
                                  derive=lambda: stability.static_recipe(self.system))


def _ends(axes: Mapping) -> list[dict[str, float]]:
    """The corners of the engine's ``axes`` (name -> values): each axis at its least and its largest value."""
    return [{name: float(v) for name, v in zip(axes, point)}
            for point in itertools.product(*[(min(v), max(v)) for v in axes.values()])]


def open_model(request: ModelRequest) -> OpenModel:
    """The model of ``request`` opened for a run (its start-up cache slot read: nothing loaded yet)."""
    return OpenModel(request)
