"""Files that belong together (a report's page, its data and figures), replaced together or not at all.

One file is written whole by a rename (:func:`gearsym.files.atomic.write_atomically`); a set of them cannot be
renamed at once. So the new set is written into a staging folder beside the old one first, where a failure
or a kill leaves the old set as it was. Then a marker file is put in the folder, saying that it holds a mix
of two runs; the files are renamed into place with Ctrl-C and SIGTERM held back (they take effect after);
and the marker is removed. Only a kill that cannot be held back (``kill -9``, a power cut) within those
renames leaves the mix, and the marker says so.
"""
from __future__ import annotations

import os
import secrets
import shutil
import signal
import threading
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

from ..errors import GearsymError
from .atomic import write_atomically
from .lock import process_alive

_STAGING = ".gearsym-staging-"


@contextmanager
def written_together(folder: str | Path, names: Sequence[str], marker: str, what: str) -> Iterator[Path]:
    """A staging folder to write the files ``names`` into; when the block ends normally, they replace those of
    ``folder`` together (the folder is made if missing). Left with an error, nothing in ``folder`` changes, and a
    failure of the system (the disk full) is a one-line error. ``marker``: the name of the file that says the
    folder is partial while the files are renamed (it names ``what`` they are)."""
    folder = Path(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
        _remove_abandoned(folder)
        stage = folder / f"{_STAGING}{os.getpid()}-{secrets.token_hex(4)}"
        stage.mkdir()
    except OSError as exc:
        raise GearsymError(f"cannot write {what} into {folder}: {exc.strerror or exc}") from None
    replacing = False
    try:
        yield stage
        missing = [n for n in names if not (stage / n).is_file()]
        if missing:
            raise GearsymError(f"{what}: {', '.join(missing)} was not written")
        blocked = [n for n in names if (folder / n).is_dir()]  # (a rename over it would fail halfway)
        if blocked:
            raise GearsymError(f"{folder / blocked[0]} is a folder, so {what} cannot be written there; move it away "
                               "or choose another --out (nothing was changed)")
        note = (f"This folder holds parts of two runs: {what} was being replaced when the run was stopped. "
                f"Run the command again; until then, do not trust {', '.join(names)}.\n")
        with _signals_held():
            write_atomically(folder / marker, note)
            replacing = True
            for name in names:
                os.replace(stage / name, folder / name)
            (folder / marker).unlink()
    except OSError as exc:
        state = f"it is partial, as {marker} there says" if replacing else "what was there before is unchanged"
        raise GearsymError(f"writing {what} into {folder} failed: {exc.strerror or exc}; {state}") from None
    finally:
        shutil.rmtree(stage, ignore_errors=True)


@contextmanager
def _signals_held() -> Iterator[None]:
    """Ctrl-C and SIGTERM held back in the block (delivered after it), where the process can hold them."""
    held = {signal.SIGINT, signal.SIGTERM}
    if threading.current_thread() is not threading.main_thread() or not hasattr(signal, "pthread_sigmask"):
        yield
        return
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, held)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)


def _remove_abandoned(folder: Path) -> None:
    """Staging folders of runs that were killed (their process is gone)."""
    for path in folder.glob(f"{_STAGING}*"):
        try:
            pid = int(path.name[len(_STAGING):].split("-")[0])
        except ValueError:
            continue
        if pid != os.getpid() and not process_alive(pid) and path.is_dir() and not path.is_symlink():
            shutil.rmtree(path, ignore_errors=True)
