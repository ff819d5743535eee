"""Planetary differential: the planetary set of models/planetary.py with its ring gear free.

Sun and ring both drive (their mean torques in the ratio of the teeth, so that each planet is in balance),
the carrier carries the load: six bodies for three planets and two rigid-body modes (the two inputs can turn
at any ratio), so the reduction keeps N + 1 deflections again and every other ring mesh is a combination of
them. With several rigid-body modes the kinematics leave the direction of the central gears relative to the
carrier open; the mesh phases take the sun forward and the ring backward relative to it, as with the ring held.
"""
from models.planetary import build

model = build(name="planetary_differential", ring_fixed=False)
