"""Finding and loading models by name (``models/<name>.py``) or by file path: names and files to models, and
nothing else (values, units and reductions are the caller's: :mod:`gearsym.loading`)."""
from __future__ import annotations

import ast
import importlib
import importlib.util
import sys
import traceback
from pathlib import Path
from typing import Union

from .model.declared import Model
from .errors import GearsymError, ModelError, suggest, warn
from .files.kinds import what_is_at
from .files.paths import MODELS_DIR


def models_dir() -> Path:
    """``./models`` if the working directory has one, else the shipped models (:data:`~.paths.MODELS_DIR`)."""
    local = Path.cwd() / "models"
    return local if (local / "__init__.py").is_file() else MODELS_DIR


def output_root(ref) -> Path:
    """Where a model's derivation page (``docs/derivations/``) and C (``generated/``) go by default: the current
    directory, whatever the model (a command never writes into the installed tree; run from the repository's
    root, it regenerates the committed pages and C)."""
    return Path.cwd()


def available_models() -> list[str]:
    d = models_dir()
    return sorted(p.stem for p in d.glob("*.py") if not p.stem.startswith("_") and p.is_file())


def pregenerated_models(what: str = "code") -> list[str]:
    """The models whose C (``what="code"``: ``generated/``) or derivation page (``"page"``: ``docs/derivations/``)
    is committed: what ``gearsym compile --all`` and ``gearsym fmu --all``, or ``gearsym docs --all``, make. A model
    file that sets ``PREGENERATED = False`` is shipped and runs by name, but is derived and compiled on its first
    use only; ``PREGENERATED = "code"``: its C is committed, its page not (Lin & Parker's translational set, whose
    page of formulas would be a megabyte)."""
    if what not in ("code", "page"):
        raise ValueError(f"what is 'code' or 'page', not {what!r}")
    flags = {name: _pregenerated_flag(models_dir() / f"{name}.py") for name in available_models()}
    return [name for name, flag in flags.items() if flag is True or flag == what]


def _pregenerated_flag(path: Path) -> bool | str:
    """A model file's ``PREGENERATED`` (True when it sets none), read from its text: listing the committed models
    does not run every model file (each builds its model, some their gears' stiffness, when it runs)."""
    try:
        body = ast.parse(path.read_bytes(), filename=str(path)).body
    except SyntaxError as exc:
        raise GearsymError(f"{exc.filename}, line {exc.lineno}: {type(exc).__name__}: {exc.msg}") from None
    for node in body:
        targets = node.targets if isinstance(node, ast.Assign) else [node.target] if isinstance(node, ast.AnnAssign) \
            else []
        if any(isinstance(t, ast.Name) and t.id == "PREGENERATED" for t in targets) and node.value is not None:
            try:
                flag = ast.literal_eval(node.value)
            except ValueError:
                flag = None
            if not (isinstance(flag, bool) or flag == "code"):
                raise GearsymError(f"{path}, line {node.lineno}: PREGENERATED is True, False or \"code\", written as "
                                   "such (the file is read, not run, to list the committed models)")
            return flag
    return True


def model_path(ref: str) -> Path | None:
    """The file (resolved) of a model name or path; None if there is none (:func:`load_model` says why). A name
    that the working directory's ``models/`` gives another file than the shipped model of that name is said
    in a warning: the working directory decides what runs."""
    try:
        if _is_path(ref):
            path = Path(ref)
        elif ref.isidentifier():
            path = models_dir() / f"{ref}.py"
            _say_if_shadowed(ref, path)
        else:
            return None
        return path.resolve() if path.is_file() else None
    except OSError:  # (a name too long for the system, ...)
        return None


_SHADOWED: set[Path] = set()  # said already


def _say_if_shadowed(name: str, path: Path) -> None:
    shipped = MODELS_DIR / f"{name}.py"
    if path.parent.resolve() == shipped.parent.resolve() or not shipped.is_file() or path in _SHADOWED:
        return
    _SHADOWED.add(path)
    warn(f"model {name} is {path} (the models/ of the working directory), not the shipped {shipped}")


def _is_path(ref: str) -> bool:
    return ref.endswith(".py") or "/" in ref


def _shown(ref: str, quote=str) -> str:
    """``ref`` as an error message shows it (``quote``: ``repr`` for a name); one of thousands of characters cut."""
    return quote(ref) if len(ref) <= 80 else f"{quote(ref[:60])}... ({len(ref)} characters)"


def load_model(ref: Union[str, Path, Model], options: dict | None = None) -> Model:
    """A model object from a name in ``models/``, a path to a ``.py`` file, or a model itself; ``options`` are
    model options its file declares (``OPTIONS = {"planets": 3}``), given to its ``build`` (``--set planets=4``)."""
    if isinstance(ref, Model):
        if options:
            raise GearsymError(f"{ref.name}: model options ({', '.join(options)}) need a model file's build, not a "
                               "model object")
        return ref
    module = _module(ref)
    if not options:
        return _model_of(module, ref)
    declared = model_options(ref)
    options = dict(options)
    for name, value in list(options.items()):
        if name not in declared:
            raise GearsymError(f"{_model_of(module, ref).name} has no model option {name!r} (its options: "
                               f"{', '.join(declared) or 'none'})")
        if isinstance(value, str):
            try:
                value = float(value)
            except ValueError:
                raise GearsymError(f"--set {name}={value}: the model option {name} is a number") from None
        if isinstance(value, bool) or not isinstance(value, (int, float)) or value != value or abs(value) == float("inf"):
            raise GearsymError(f"the model option {name} is a finite number, got {value!r}")
        options[name] = int(value) if float(value).is_integer() else float(value)
    key = (id(module), tuple(sorted(options.items())))
    if key not in _BUILT:  # (one model per options and module: its reduction is cached on it)
        _BUILT[key] = (module, _with_models_importable(lambda: module.build(**options), Path(module.__file__)))
    return _BUILT[key][1]


def model_options(ref) -> dict:
    """The model options a model's file declares (``OPTIONS``: name -> default), none for a model object."""
    if isinstance(ref, Model):
        return {}
    options = getattr(_module(ref), "OPTIONS", None)
    return dict(options) if isinstance(options, dict) else {}


_BUILT: dict[tuple, tuple] = {}  # (module, options) -> (the module, kept alive; its model with those options)


def _model_of(module, ref) -> Model:
    model = getattr(module, "model", None)
    if not isinstance(model, Model):
        raise ModelError(
            "a model file must define `model`, a Drivetrain or a FirstOrderSystem", getattr(module, "__file__", ref)
        )
    return model


def _module(ref):
    """The module of a model name or file (run once)."""
    ref = str(ref)
    path = model_path(ref)
    if _is_path(ref):
        if path is None:
            raise GearsymError(f"model file {_shown(ref)} {_what_is_there(ref)}")
        if path.suffix != ".py":
            raise GearsymError(f"{ref} is not a model file: a model file is Python, named *.py (e.g. models/"
                               "one_stage.py), and a model name is one of `gearsym list`")
        spec = importlib.util.spec_from_file_location(f"gearsym_user_model_{path.stem}", path)
        module = importlib.util.module_from_spec(spec)
        _with_models_importable(lambda: spec.loader.exec_module(module), path)
    else:
        names = available_models()
        if ref not in names or path is None:
            raise GearsymError(
                f"unknown model {_shown(ref, repr)}.{suggest(ref, names) if len(ref) <= 80 else ''} Models in "
                f"{models_dir()}: {', '.join(names)}; or give the path of a model file."
            )
        module = _with_models_importable(lambda: importlib.import_module(f"models.{ref}"))
    return module


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
    except (Exception, SystemExit) as exc:  # (a model file that exits would end gearsym, with its status)
        frames = traceback.extract_tb(exc.__traceback__)
        models = [f for f in frames if not f.filename.startswith("<") and Path(f.filename).parent.resolve() in folders]
        where = (models or frames)[-1]  # the model file's own line, not one in a library it called
        if isinstance(exc, SystemExit):
            raise GearsymError(f"{where.filename}, line {where.lineno}: the model file calls exit ({exc.code!r}) "
                               "while it is loaded; a model file defines `model` and must not exit") from None
        raise GearsymError(f"{where.filename}, line {where.lineno}: {type(exc).__name__}: {exc}") from None
    finally:
        if added:
            sys.path.remove(root)


def model_file(ref: str) -> Path | None:
    """The file of a model name or path (None for a name that is no model, or a file that is none: the loader
    says why)."""
    path = model_path(ref)
    return path if path is not None and path.suffix == ".py" else None


def _what_is_there(ref: str) -> str:
    """Why ``ref`` is no model file: what stands at that path instead (a folder, a pipe, a device), or nothing."""
    return what_is_at(Path(ref), "a model file is a Python file (*.py)")

