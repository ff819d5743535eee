"""The forced Duffing oscillator, declared through the low-level first-order entry.

Not a gear model: x'' + 2 zeta x' + x + beta x^3 = F cos(omega t), whose frequency response bends to
the right and folds (two saddle-nodes bound a hysteresis interval), the textbook check of a
continuation of periodic orbits (``gearsym orbits duffing --param omega=0.5:2.0``). Time is t, so the
forcing period 2 pi/omega changes with omega.
"""
from gearsym import FirstOrderSystem

model = FirstOrderSystem.from_equations(
    "duffing",
    states=["x", "v"],
    rhs=["v", "-2*zeta*v - x - beta*x**3 + F*cos(omega*t)"],
    parameters={"zeta": 0.05, "beta": 0.2, "F": 0.3, "omega": 1.2},
    time="t",
    period="2*pi/omega",
    initial={"x": 0.0, "v": 0.0},
    descriptions={"zeta": "damping ratio", "beta": "cubic stiffness (hardening for beta > 0)",
                  "F": "forcing amplitude", "omega": "forcing frequency (the linear natural frequency is 1)"},
    title="Forced Duffing oscillator: a plain ODE for the continuation of periodic orbits",
)
