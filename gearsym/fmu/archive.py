"""The FMU's zip archive, the same bytes for the same files: entries sorted by name, one fixed time stamp
(1980-01-01, zip's earliest), fixed permissions, one compression level; nothing of the machine that wrote it."""
from __future__ import annotations

import io
import zipfile
from collections.abc import Mapping
from pathlib import Path

from ..files.atomic import write_atomically

#: the time stamp of every entry (zip's epoch: no build date in the archive)
STAMP = (1980, 1, 1, 0, 0, 0)


def archive_bytes(files: Mapping[str, bytes]) -> bytes:
    """The zip of ``files`` (path in the archive -> content; "/" separated, relative)."""
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w") as zf:
        for name in sorted(files):
            if name.startswith("/") or "\\" in name or ".." in name.split("/"):
                raise ValueError(f"{name!r} is not a relative path inside the archive")
            info = zipfile.ZipInfo(name, STAMP)
            info.compress_type = zipfile.ZIP_DEFLATED
            info.create_system = 3  # Unix: the permissions below are read as such everywhere
            info.external_attr = (0o100755 if name.startswith("binaries/") else 0o100644) << 16
            zf.writestr(info, files[name], compress_type=zipfile.ZIP_DEFLATED, compresslevel=9)
    return buffer.getvalue()


def write_archive(path: Path, files: Mapping[str, bytes]) -> Path:
    """``path`` written whole or not at all."""
    return write_atomically(path, archive_bytes(files))
