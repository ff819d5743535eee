"""Notes relating a derived model to the paper (Litak & Friswell, Eqs. 1-10).

The docs say where gearsym departs from, completes or corrects the printed
equations, so that a reader comparing them with the paper is not left to
guess. Each note is triggered by a feature of the model (a mesh with
backlash, the default stiffness wave, derived groups, a condition), never by
the model's name, so a new model gets exactly the notes that apply to it.
Notes are Unicode text with code in backticks (Markdown's code spans): they
read the same in a terminal, in JSON and in Markdown.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence

from ..model.expressions import parameter_names
from ..model.roles import default_wave_amplitude
from ..model.stiffness import DEFAULT_CONTACT_RATIO, DEFAULT_HARMONICS
from ..reduction.nondimensional import NondimensionalModel
from .printing import number
from .records import GroupRecord


def paper_notes(nd: NondimensionalModel, groups: Sequence[GroupRecord], defaults: Mapping[str, float]) -> tuple[str, ...]:
    """The notes that apply to ``nd`` (a reduced drivetrain)."""
    meshes = [rc for rc in nd.reduction.resolved.couplings if rc.kind == "mesh"]
    notes: list[str] = []
    if any(rc.backlash != 0 for rc in meshes):
        notes.append(
            "Backlash (Eq. 5): the paper prints the third branch of g(x, η) as x ≤ η; the continuous "
            "function meant, and used here (`gearsym.model.backlash.g`), has x ≤ −η: g = x for x ≥ 0, "
            "0 for −η < x < 0, x + η for x ≤ −η."
        )
    waves = [(fn.name, default_wave_amplitude(rc.variation)) for rc, fn in zip(meshes, nd.functions)]
    waves = [(name, amplitude) for name, amplitude in waves if amplitude is not None]
    if waves:
        functions = ", ".join(f"{name}(τ)" for name, _ in waves)
        amplitudes = ", ".join(
            f"{amplitude} = {number(defaults[amplitude])}" if amplitude in defaults else amplitude
            for _, amplitude in waves
        )
        notes.append(
            f"Mesh stiffness {functions}: the paper shows k(τ) only as a plot (its Fig. 2), so gearsym declares a "
            "default, `gearsym.model.stiffness.rectangular_mesh_stiffness`: a rectangular wave for contact ratio "
            f"{number(DEFAULT_CONTACT_RATIO)} (double-tooth contact during "
            f"{number(round((DEFAULT_CONTACT_RATIO - 1) * 100, 6))} % of each mesh period), smoothed to "
            f"{DEFAULT_HARMONICS} Fourier harmonics with Lanczos factors, mean 1, relative amplitude {amplitudes}. "
            "Replace it with `Mesh(variation=...)`."
        )
    for rc, fn in zip(meshes, nd.functions):
        computed = rc.component.computed
        if computed is not None:
            notes.append(
                f"Mesh stiffness {fn.name}(τ) of mesh '{rc.name}', from the gears' geometry (`Mesh.from_gears`, "
                f"docs/geometry.md): {computed.describe()}. The potential-energy method gives the stiffness over a "
                f"mesh period; its mean is the value of {rc.component.stiffness}, and the variation above is its "
                "Fourier series over that mean."
            )
    derived = [gr for gr in groups if gr.kind == "derived"]
    if derived and not nd.drivetrain.physical:  # (a model with physical values gives them: its scaling's section)
        behind = sorted(set().union(*(parameter_names(gr.definition) for gr in derived)))
        values = ", ".join(f"{n} = {number(defaults[n])}" for n in behind if n in defaults)
        results = ", ".join(f"{gr.name} = {number(gr.value)}" for gr in derived if gr.value is not None)
        notes.append(
            f"Inertias and radii: the paper gives no values for them; the derived groups "
            f"{', '.join(gr.name for gr in derived)} are evaluated from the declared parameters "
            f"{', '.join(behind)}, whose defaults in the model file ({values}) give {results}."
        )
    for cond in nd.conditions:
        if cond.kind == "time_unit":
            notes.append(
                "Time unit: Eq. 4 folds the mean mesh stiffness into k(τ) without stating the time unit; here "
                "t is measured in units of 1/ω_n, ω_n² being the first mesh's mean stiffness times its "
                "inertia factor (the time-unit condition), so k(τ) has the mean of the declared variation."
            )
        elif cond.kind == "torque_balance":
            notes.append(
                "Torque balance: the constant torques must satisfy the torque-balance condition above, "
                "the last line of the paper's Eq. 10, for the twist equation to carry no constant forcing."
            )
    return tuple(notes)
