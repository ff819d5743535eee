"""The packages of gearsym's wheel (everything else is in pyproject.toml).

gearsym's own packages are found in the tree; the shipped models (``models/``) and their generated C
(``generated/<model>/``) are added under the names they have once installed, ``gearsym.shipped.models`` and
``gearsym.shipped.generated`` (pyproject.toml maps them to the repository's top-level folders). A search of
the tree cannot find a package under a name mapped to another folder, and pyproject.toml takes either a
search or a list, not both: so the list is made here, and a new subpackage of gearsym (or a new model's
folder of C) is found without a word.
"""
from setuptools import find_namespace_packages, setup

OWN = find_namespace_packages(include=["gearsym", "gearsym.*"], exclude=["*.__pycache__"])
GENERATED = [f"gearsym.shipped.generated.{name}" for name in find_namespace_packages(where="generated")]

setup(packages=[*OWN, "gearsym.shipped.models", "gearsym.shipped.generated", *GENERATED])
