"""Where the package's own folders are: the repository it was installed from, its models and generated code.

One place for them, so that the model registry, the code generator and the command line agree without
importing each other.
"""
from __future__ import annotations

from pathlib import Path

#: the repository checkout this package was installed from (editable installs)
REPO_ROOT = Path(__file__).resolve().parents[2]
#: the committed C of the shipped models, one folder per model
GENERATED_DIR = REPO_ROOT / "generated"
