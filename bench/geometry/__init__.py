"""``python -m bench.geometry``: how long a mesh-stiffness curve takes (issue 27's targets: spur < 0.5 s, helical with
20 slices < 2 s)."""
