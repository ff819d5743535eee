"""Finding and loading models by name (``models/<name>.py``) or by file path."""
from __future__ import annotations

import importlib
import importlib.util
import sys
import traceback
from pathlib import Path
from typing import TYPE_CHECKING, Union

from .errors import GearsymError, ModelError, suggest
from .paths import REPO_ROOT

if TYPE_CHECKING:  # (imported where used: SymPy, which finding a model's file does not need)
    from .model.drivetrain import Drivetrain
    from .system import FirstOrderSystem

Model = Union["Drivetrain", "FirstOrderSystem"]


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
    from .model.drivetrain import Drivetrain
    from .system import FirstOrderSystem

    if isinstance(ref, (Drivetrain, FirstOrderSystem)):
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
    if not isinstance(model, (Drivetrain, FirstOrderSystem)):
        raise ModelError(
            "a model file must define `model`, a Drivetrain or a FirstOrderSystem", getattr(module, "__file__", ref)
        )
    return model


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


def load(ref, **values) -> FirstOrderSystem:
    """The first-order system of a model, ready for the engine: the one place names and files are resolved.

    ``ref`` is a model name (``models/<name>.py``), the path of a model file, a Drivetrain, a reduced
    NondimensionalModel or a FirstOrderSystem. ``values`` give parameter values (``omega=1.5``) or, for a
    drivetrain, a new mesh stiffness as a formula in tau (``k="1 + 0.2*cos(tau)"``). Strings that read as
    numbers are numbers. A drivetrain with physical values (``model.set_physical``), or given one here
    (``kZ="2e8 N/m"``, ``speed="3000 rpm"``, a pint Quantity; ``length_scale="backlash"``), is scaled to its
    nondimensional values by :class:`gearsym.physical.Scaling`.
    """
    from .reduce import NondimensionalModel, reduce
    from .system import FirstOrderSystem

    model = ref if isinstance(ref, NondimensionalModel) else load_model(ref)
    values = {k: _maybe_number(v) for k, v in values.items()}
    split = physical_settings(model, values)
    if split is not None:
        from .physical.scales import scaling

        length_scale, physical, formulas = split
        return scaling(model, length_scale, **physical).system(**formulas)
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


def physical_settings(model, values: dict):
    """For a model with physical values (declared, or given in ``values``: a quantity, a pint Quantity or a
    length scale): (length scale or None, physical values, stiffness formulas); else None."""
    from .physical.text import looks_like_quantity

    declared = model.drivetrain if hasattr(model, "drivetrain") else model
    given = "length_scale" in values or any(
        type(v).__module__.startswith("pint") or (isinstance(v, str) and looks_like_quantity(v)) for v in values.values())
    if not (given or getattr(declared, "physical", None)):
        return None
    from .system import FirstOrderSystem

    if isinstance(model, FirstOrderSystem):
        raise GearsymError(f"{model.name}: physical values need a drivetrain model (a FirstOrderSystem has no "
                           "components to give them units)")
    functions = _function_names(model)
    values = {k: _maybe_number(v) for k, v in values.items()}
    length_scale = values.pop("length_scale", None)
    return (length_scale, {k: v for k, v in values.items() if k not in functions},
            {k: v for k, v in values.items() if k in functions})


def _function_names(model) -> set[str]:
    """The names of a drivetrain's stiffness functions (``k``), which take a formula, not a physical value."""
    from .reduce import reduce

    nd = model if hasattr(model, "functions") else reduce(model)
    return {f.name for f in nd.functions}


def _maybe_number(value):
    if isinstance(value, str):
        try:
            return float(value)
        except ValueError:
            return value.strip()
    return value
