"""One-stage gear pair with the weak resonant excitation D cos(tau + Theta') (the paper's Eq. 6).

Declared as a second harmonic of the driving torque with its own phase; the
reduction turns its amplitude into the group D. Paper values: D = 2, Theta' = 0.1.
"""
from models.one_stage import build

model = build("one_stage_resonant", resonant=True)
