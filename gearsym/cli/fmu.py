"""``gearsym fmu MODEL --out F.fmu`` (or ``--all --out DIR``): the model as an FMI 2.0 FMU, co-simulation and
model exchange, with this platform's binary and the C sources (docs/fmu.md)."""
from __future__ import annotations

import argparse
from pathlib import Path

from ..errors import GearsymError
from ..fmu.export import export_fmu
from ..files.outputs import check_folder
from ..registry import pregenerated_models, load_model
from .arguments.integration import add_integration_arguments, integration_from
from .arguments.settings import add_set_argument, model_settings

NAME = "fmu"
HELP = "export the model as an FMI 2.0 FMU (co-simulation and model exchange) for Modelica tools, Simulink, FMPy"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("model", nargs="?", help="a model name (see `gearsym list`) or the path of a model file")
    parser.add_argument("--all", action="store_true",
                        help="every model of `gearsym list` whose C is committed, as DIR/<model>.fmu")
    add_set_argument(parser)
    add_integration_arguments(parser, periods=None, steps_help="RK4 steps per forcing period of the default "
                              "experiment's communication step (default 200)")
    parser.add_argument("--out", type=Path, required=True, metavar="F.fmu",
                        help="the FMU to write (a file name ending in .fmu in an existing folder); with --all, the "
                             "folder the FMUs go into (made if missing)")


def run(args: argparse.Namespace) -> int:
    if bool(args.all) == bool(args.model):
        raise GearsymError("give a model or --all (not both), e.g. gearsym fmu one_stage --out one_stage.fmu")
    settings = model_settings(args)
    options = integration_from(args)
    if args.all:
        folder = check_folder(args.out)
        refs = pregenerated_models()
        targets = [folder / f"{ref}.fmu" for ref in refs]
    else:
        load_model(args.model)  # an unknown model or a broken file: one line, before anything else
        targets, refs = [check_fmu_path(args.out)], [args.model]
    for ref, target in zip(refs, targets):
        done = export_fmu(ref, target, options=options, **settings)
        kind = "SI (s, m, m/s, N)" if done.physical else "nondimensional"
        print(f"{done.model}: {done.path} ({done.size / 1024:.0f} KiB; co-simulation and model exchange, "
              f"{done.variables} variables ({kind}), {done.event_indicators} event indicators; built in "
              f"{done.seconds:.1f} s, {done.compile_seconds:.1f} s of it compiling)")
    return 0


def check_fmu_path(path: Path) -> Path:
    """``path`` as an FMU to write: a name ending in .fmu, in a folder that exists and can be written."""
    if path.suffix.lower() != ".fmu":
        got = f"{path.suffix!r} is not .fmu" if path.suffix else "it has no suffix"
        raise GearsymError(f"--out {path}: an FMU's file name ends in .fmu ({got}); "
                           f"e.g. --out {path.stem or 'model'}.fmu")
    if path.is_dir():
        raise GearsymError(f"--out {path} is a folder; give a file name ending in .fmu (or --all for a folder)")
    folder = path.parent
    if not folder.is_dir():
        raise GearsymError(f"--out {path}: the folder {folder} does not exist; make it first or write elsewhere")
    check_folder(folder)
    return path

