"""How a parameter is written where results are shown (titles, the command's text): its symbol and value; and the
"parameters:" line of a command's text, in the user's units for a model with physical values."""
from __future__ import annotations

#: how titles write a parameter's name
SYMBOLS = {"omega": "ω", "zeta": "ζ", "eta": "η", "Theta": "Θ", "Theta_p": "Θ'", "kS": "$k_S$", "k_a": "$k_a$"}


def parameter_text(name: str, value: float) -> str:
    """'ω=1.5', 'k_S=0.1': a parameter as titles show it."""
    return f"{SYMBOLS.get(name, name)}={value:g}"


def parameters_line(parameters: dict, units=None) -> str:
    """The values a run was made at, as a command's text says them: for a model with physical values (``units``,
    its :class:`~gearsym.physical.point.PointUnits`) every physical value as the model or the user gave it (the
    engine's nondimensional numbers, named like the physical values they are made of, would read as those values
    in other units: they are in the JSON); else the model's own numbers."""
    if units is None:
        return ", ".join(f"{k}={v:g}" for k, v in parameters.items())
    return units.parameters_text() + " (the engine's nondimensional values: --format json)"
