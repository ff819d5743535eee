"""The models shipped with gearsym; each module exposes ``model``.

Load them by name (``gearsym derive flexible_shaft``) or with
:func:`gearsym.load_model`. A model file elsewhere is loaded by its path.
"""
