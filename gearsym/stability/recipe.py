"""What a stability chart about the static state runs on, as data (no SymPy): the static problem of a model and its
compiled linearisation. The start-up cache keeps both (``gearsym/cached.py``), so that a chart of a cached model
needs neither the reduction nor the code generator."""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import field

from ..records import record_class
from ..codegen.compiled import CompiledModel

#: the suffix of the parameters that carry the static state into the linearised system
STATIC_SUFFIX = "_static"


def anchor_parameter(state: str) -> str:
    """The parameter of the linearised system that holds the static value of ``state``."""
    return f"{state}{STATIC_SUFFIX}"


@record_class
class StaticRecipe:
    """The static state of a model as a problem in numbers: ``unknowns`` (the states not at rest) solve
    residual(unknowns, parameters) = 0, the other states being 0 (rates at rest). The residual depends only on
    the parameters ``depends`` (the rows' own parameter factors taken out: omega in the tau-form does not move
    the static state), so a chart solves it once per distinct value of those. ``function``: a serialised CasADi
    function (unknowns, depends) -> (residual, d residual / d unknowns, contact deflection of each mesh with
    backlash, its backlash); ``meshes``: their names."""

    states: tuple[str, ...]
    unknowns: tuple[str, ...]
    depends: tuple[str, ...]
    meshes: tuple[str, ...]
    function: str = field(repr=False)

    def as_dict(self) -> dict:
        return {"states": list(self.states), "unknowns": list(self.unknowns), "depends": list(self.depends),
                "meshes": list(self.meshes), "function": self.function}

    @classmethod
    def from_dict(cls, d: dict) -> "StaticRecipe":
        return cls(tuple(map(str, d["states"])), tuple(map(str, d["unknowns"])), tuple(map(str, d["depends"])),
                   tuple(map(str, d["meshes"])), str(d["function"]))


@record_class
class CompiledLinearisation:
    """A model's linearisation about its static state, compiled: the linear system's compiled model, the static
    recipe, the states its Jacobian depends on, and the model's own name and parameters (a chart's axes)."""

    model: CompiledModel
    recipe: StaticRecipe
    anchors: tuple[str, ...]
    base: str
    base_parameters: Mapping[str, float]
    physical: bool = False  # the model has physical values (its chart's axes may carry units)
