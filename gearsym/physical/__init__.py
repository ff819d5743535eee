"""Results carried back to the user's units (rpm, µm, N, 1/s): the stage above the analyses it converts.

:mod:`.answers` (the :class:`~.answers.PhysicalScaling` the face's ``gearsym.scaling`` returns, with
``to_physical``), :mod:`.results` (spectra, trajectories and sweeps in physical units), :mod:`.point` (one
operating point from cached numbers: the start-up path, no pint and no SymPy), :mod:`.sweeps` (physical
sweep axes), :mod:`.orbits` (branches of periodic orbits along the speed), :mod:`.campbell` and
:mod:`.files`. The modules are imported by name, so the light :mod:`.point` never loads the others.
"""
