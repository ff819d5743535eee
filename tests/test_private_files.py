"""Files that hold code or what vouches for it are read only if they are the user's own and nobody else can write
them (gearsym/files/private.py): each refusal with its reason, and the files that pass."""
from __future__ import annotations

import os

import pytest

from gearsym.files.private import NotPrivate, read_private, write_private

NOBODY = 65534


def test_a_file_of_ones_own_that_nobody_else_can_write_is_read(tmp_path):
    path = write_private(tmp_path / "f", b"data")
    assert read_private(path) == b"data"
    assert os.stat(path).st_mode & 0o777 == 0o600


@pytest.mark.parametrize("mode", [0o602, 0o606, 0o666, 0o777], ids=oct)
def test_a_file_anyone_can_write_is_refused_with_its_mode(tmp_path, mode):
    path = write_private(tmp_path / "f", b"data")
    os.chmod(path, mode)
    with pytest.raises(NotPrivate, match=rf"is writable by others \(mode 0{mode:o}\)"):
        read_private(path)


def test_a_symlink_is_refused_not_followed(tmp_path):
    target = write_private(tmp_path / "target", b"data")
    (tmp_path / "link").symlink_to(target)
    with pytest.raises(NotPrivate, match="is a symlink"):
        read_private(tmp_path / "link")


def test_a_folder_where_a_file_should_be_is_refused_in_words(tmp_path):
    (tmp_path / "d").mkdir()
    with pytest.raises(NotPrivate, match="is not a regular file"):
        read_private(tmp_path / "d")


@pytest.mark.skipif(os.geteuid() != 0, reason="giving a file to another user needs root")
def test_a_file_that_belongs_to_someone_else_is_refused_with_its_owner(tmp_path):
    path = write_private(tmp_path / "f", b"data")
    os.chown(path, NOBODY, NOBODY)
    with pytest.raises(NotPrivate, match=rf"belongs to .*{NOBODY}.*not to you"):
        read_private(path)


def test_a_missing_file_is_missing_not_refused(tmp_path):
    with pytest.raises(FileNotFoundError):
        read_private(tmp_path / "none")
