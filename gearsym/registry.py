"""Finding and loading models by name (``models/<name>.py``) or by file path: names and files to models, and
nothing else (values, units and reductions are the caller's: :mod:`gearsym.loading`)."""
from __future__ import annotations

import importlib
import importlib.util
import sys
import traceback
from pathlib import Path
from typing import Union

from .declared import Model
from .errors import GearsymError, ModelError, suggest
from .paths import REPO_ROOT


def models_dir() -> Path:
    """``./models`` if the working directory has one, else the repository's ``models/``."""
    local = Path.cwd() / "models"
    return local if (local / "__init__.py").is_file() else REPO_ROOT / "models"


def output_root(ref) -> Path:
    """Where a model's derivation page (``docs/derivations/``) and C (``generated/``) go by default: the
    repository for a model of its own ``models/``, else the current directory (a user's model must
    not write into the installed tree)."""
    shipped = (REPO_ROOT / "models").resolve()
    if isinstance(ref, (str, Path)):
        text = str(ref)
        folder = Path(text).resolve().parent if text.endswith(".py") or "/" in text else models_dir().resolve()
        if folder == shipped:
            return REPO_ROOT
    return Path.cwd()


def available_models() -> list[str]:
    d = models_dir()
    return sorted(p.stem for p in d.glob("*.py") if not p.stem.startswith("_"))


def load_model(ref: Union[str, Path, Model]) -> Model:
    """A model object from a name in ``models/``, a path to a ``.py`` file, or a model itself."""
    if isinstance(ref, Model):
        return ref
    ref = str(ref)
    if ref.endswith(".py") or "/" in ref:
        path = Path(ref)
        if not path.is_file():
            raise GearsymError(f"model file {ref} does not exist")
        spec = importlib.util.spec_from_file_location(f"gearsym_user_model_{path.stem}", path)
        module = importlib.util.module_from_spec(spec)
        _with_models_importable(lambda: spec.loader.exec_module(module), path)
    else:
        names = available_models()
        if ref not in names:
            raise GearsymError(
                f"unknown model {ref!r}.{suggest(ref, names)} Models in {models_dir()}: {', '.join(names)}; "
                "or give the path of a model file."
            )
        module = _with_models_importable(lambda: importlib.import_module(f"models.{ref}"))
    model = getattr(module, "model", None)
    if not isinstance(model, Model):
        raise ModelError(
            "a model file must define `model`, a Drivetrain or a FirstOrderSystem", getattr(module, "__file__", ref)
        )
    return model


def model_module(name: str):
    """The module of a model of ``models/`` by name, with everything its file defines beside ``model`` (a
    builder such as ``build(planets)``, its constants): what ``import models.<name>`` gives in a clone, for a
    script that runs anywhere."""
    if name.endswith(".py") or "/" in name:
        raise GearsymError(f"model_module takes the name of a model in {models_dir()} (see gearsym list), not a "
                           f"file: {name!r}; import your own file as any Python module")
    load_model(name)  # checks the name and runs the file once
    return sys.modules[f"models.{name}"]


def _with_models_importable(action, model_file: Path | None = None):
    """Run ``action`` with the folder holding ``models/`` importable (model files import each other);
    a model file that fails to run (a syntax error, a missing import, ...) is a one-line error naming
    its file and line."""
    root = str(models_dir().parent)
    folders = {models_dir().resolve()} | ({model_file.resolve().parent} if model_file else set())
    added = root not in sys.path
    if added:
        sys.path.insert(0, root)
    try:
        return action()
    except GearsymError:
        raise
    except SyntaxError as exc:
        raise GearsymError(f"{exc.filename}, line {exc.lineno}: {type(exc).__name__}: {exc.msg}") from None
    except Exception as exc:
        frames = traceback.extract_tb(exc.__traceback__)
        models = [f for f in frames if not f.filename.startswith("<") and Path(f.filename).parent.resolve() in folders]
        where = (models or frames)[-1]  # the model file's own line, not one in a library it called
        raise GearsymError(f"{where.filename}, line {where.lineno}: {type(exc).__name__}: {exc}") from None
    finally:
        if added:
            sys.path.remove(root)


def model_file(ref: str) -> Path | None:
    """The file of a model name or path (None for a name that is no model: the loader says why)."""
    path = Path(ref) if ref.endswith(".py") or "/" in ref else models_dir() / f"{ref}.py"
    return path.resolve() if path.is_file() else None
