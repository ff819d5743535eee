"""A command's whole run as a Python caller makes it too: what was given checked against the opened model, the
model compiled, the run made and its files written (``basins.py``: the basins command's two jobs)."""
