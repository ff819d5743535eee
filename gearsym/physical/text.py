"""How a parameter is written where results are shown (titles, the command's text): its symbol and value."""
from __future__ import annotations

#: how titles write a parameter's name
SYMBOLS = {"omega": "ω", "zeta": "ζ", "eta": "η", "Theta": "Θ", "Theta_p": "Θ'", "kS": "$k_S$", "k_a": "$k_a$"}


def parameter_text(name: str, value: float) -> str:
    """'ω=1.5', 'k_S=0.1': a parameter as titles show it."""
    return f"{SYMBOLS.get(name, name)}={value:g}"
