"""The Lorenz system, declared through the low-level first-order entry.

Not a gear model: it checks the engine against published Lyapunov exponents
(sigma=10, rho=28, beta=8/3: 0.9056, 0, -14.5723).
"""
from gearsym import FirstOrderSystem

model = FirstOrderSystem.from_equations(
    "lorenz",
    states=["x", "y", "z"],
    rhs=["sigma*(y - x)", "x*(rho - z) - y", "x*y - beta*z"],
    parameters={"sigma": 10.0, "rho": 28.0, "beta": 8.0 / 3.0},
    time="t",
    period=1,
    initial={"x": 1.0, "y": 1.0, "z": 1.0},
    descriptions={"sigma": "Prandtl number", "rho": "Rayleigh number ratio", "beta": "geometric factor"},
    title="Lorenz system: a check of the engine against published Lyapunov exponents",
)
