"""Finding and loading models by name (``models/<name>.py``) or by file path."""
from __future__ import annotations

import importlib
import importlib.util
import sys
from pathlib import Path
from typing import Union

from .errors import GearsymError, ModelError, suggest
from .model.drivetrain import Drivetrain
from .paths import REPO_ROOT
from .system import FirstOrderSystem

Model = Union[Drivetrain, FirstOrderSystem]


def models_dir() -> Path:
    """``./models`` if the working directory has one, else the repository's ``models/``."""
    local = Path.cwd() / "models"
    return local if (local / "__init__.py").is_file() else REPO_ROOT / "models"


def available_models() -> list[str]:
    d = models_dir()
    return sorted(p.stem for p in d.glob("*.py") if not p.stem.startswith("_"))


def load_model(ref: Union[str, Path, Model]) -> Model:
    """A model object from a name in ``models/``, a path to a ``.py`` file, or a model itself."""
    if isinstance(ref, (Drivetrain, FirstOrderSystem)):
        return ref
    ref = str(ref)
    if ref.endswith(".py") or "/" in ref:
        path = Path(ref)
        if not path.is_file():
            raise GearsymError(f"model file {ref} does not exist")
        spec = importlib.util.spec_from_file_location(f"gearsym_user_model_{path.stem}", path)
        module = importlib.util.module_from_spec(spec)
        _with_models_importable(lambda: spec.loader.exec_module(module))
    else:
        names = available_models()
        if ref not in names:
            raise GearsymError(
                f"unknown model {ref!r}.{suggest(ref, names)} Models in {models_dir()}: {', '.join(names)}; "
                "or give the path of a model file."
            )
        module = _with_models_importable(lambda: importlib.import_module(f"models.{ref}"))
    model = getattr(module, "model", None)
    if not isinstance(model, (Drivetrain, FirstOrderSystem)):
        raise ModelError(
            "a model file must define `model`, a Drivetrain or a FirstOrderSystem", getattr(module, "__file__", ref)
        )
    return model


def _with_models_importable(action):
    """Run ``action`` with the folder holding ``models/`` importable (model files import each other)."""
    root = str(models_dir().parent)
    added = root not in sys.path
    if added:
        sys.path.insert(0, root)
    try:
        return action()
    finally:
        if added:
            sys.path.remove(root)


def load(ref, **values) -> FirstOrderSystem:
    """The first-order system of a model, ready for the engine: the one place names and files are resolved.

    ``ref`` is a model name (``models/<name>.py``), the path of a model file, a Drivetrain, a reduced
    NondimensionalModel or a FirstOrderSystem. ``values`` give parameter values (``omega=1.5``) or, for a
    drivetrain, a new mesh stiffness as a formula in tau (``k="1 + 0.2*cos(tau)"``). Strings that read as
    numbers are numbers.
    """
    from .reduce import NondimensionalModel, reduce

    model = ref if isinstance(ref, NondimensionalModel) else load_model(ref)
    values = {k: _maybe_number(v) for k, v in values.items()}
    if isinstance(model, FirstOrderSystem):
        for key, value in values.items():
            if not isinstance(value, (int, float)):
                raise GearsymError(
                    f"{model.name}: {key}={value!r} is not a number; only drivetrain models accept a formula "
                    "(a new mesh stiffness function)"
                )
        return model.with_values(**values)
    nd = model if isinstance(model, NondimensionalModel) else reduce(model)
    return nd.system(**values)


def _maybe_number(value):
    if isinstance(value, str):
        try:
            return float(value)
        except ValueError:
            return value.strip()
    return value
