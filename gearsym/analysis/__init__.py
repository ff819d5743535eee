"""Analyses on one parameter point: a high-level call on a model, or a low-level call on a prebuilt
:class:`~gearsym.codegen.CompiledModel` reused across a sweep. Each is imported from its module (the face,
:mod:`gearsym`, names the public ones), so that a command imports the analyses it runs and no others:
``gearsym lyap`` on a cached model starts without the attractors', basins' and orders' modules.

:mod:`.lyapunov` (:func:`~.lyapunov.lyapunov_spectrum`, with :mod:`.divergence`, :mod:`.pairs`,
:mod:`.resolution`, :mod:`.regime`, :mod:`.settling` and :mod:`.statistics`); :mod:`.poincare` (stroboscopic
samples and trajectories); :mod:`.attractors` (coexisting attractors from many starts, their spectra at once in
the lanes: :mod:`.lane_spectra`) and :mod:`.basins` (basins of attraction); :mod:`.jumps` (jumps and hysteresis
along a continuation); :mod:`.orders` and :mod:`.order_run` (order spectra); :mod:`.modes` (natural frequencies
and mode shapes).
"""
