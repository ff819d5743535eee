"""Where the package's own folders are: the shipped models and their generated code, and the folder holding gearsym.

One place for them, so that the model registry, the code generator and the command line agree without
importing each other.

The repository keeps ``models/`` and ``generated/`` at its top level, beside ``gearsym/``: a clone (an editable
install, or ``PYTHONPATH`` pointing at it) runs its models and regenerates their C there. A wheel or a
non-editable ``pip install`` carries the same folders inside gearsym's namespace, as ``gearsym/shipped/models``
and ``gearsym/shipped/generated`` (``pyproject.toml`` maps them, ``setup.py`` lists them), so that nothing of
gearsym lands at the top of site-packages. Which of the two this is, is decided here by looking at the files,
not through the import system: an editable install maps packages with an import hook that a
``PYTHONPATH=<clone>`` run (as the tests use) does not have, while the files are where they are in every case.
The models folder keeps its package name, ``models``, wherever it lies (model files import each other as
``models.<name>``, in a clone, in an installed gearsym and in a user's own ``./models/``; :mod:`gearsym.registry`
puts its parent folder on the import path while it loads one).
"""
from __future__ import annotations

from pathlib import Path

#: the folder of gearsym's own code (this file is in gearsym/files/)
PACKAGE_DIR = Path(__file__).resolve().parents[1]
#: the folder holding gearsym: in a clone, the repository's root (its docs/, tests/, models/ and generated/)
REPO_ROOT = PACKAGE_DIR.parent
#: where an installed gearsym (a wheel, a non-editable install) carries its models and their C
INSTALLED_DIR = PACKAGE_DIR / "shipped"
#: the folder holding the shipped ``models/`` package and ``generated/``: the installed copy if there is one,
#: else the clone's root
SHIPPED_DIR = INSTALLED_DIR if (INSTALLED_DIR / "models" / "__init__.py").is_file() else REPO_ROOT
#: the shipped models, one file each (the package ``models``)
MODELS_DIR = SHIPPED_DIR / "models"
#: the committed C of the shipped models, one folder per model
GENERATED_DIR = SHIPPED_DIR / "generated"
