"""The physical <-> nondimensional map of a reduced drivetrain (just above the reduction that defines it).

:class:`~.map.Scaling` is made from a :class:`~gearsym.reduction.NondimensionalModel` and physical values
in SI (:class:`~gearsym.units.Measure`); it gives the engine's values and the numbers that carry results
back (:mod:`gearsym.physical`, above the analyses, does the carrying). :mod:`.speeds` (the operating speed,
light: the start-up path reads it), :mod:`.roles` and :mod:`.dimensions` (what each value is, checked),
:mod:`.settings` (physical values told from nondimensional ones). The modules are imported by name: this
package's face hands nothing on, so reading one light module never loads the SymPy-heavy map.
"""
