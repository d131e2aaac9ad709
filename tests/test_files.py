"""Files written whole or not at all, and the temporaries of killed runs cleaned up."""

import os
import stat

import pytest

from biped.errors import BipedError
from biped.records import gait_file
from biped.runtime import files


def _listing(folder):
    return sorted(p.name for p in folder.iterdir())


def test_write_text_replaces_the_file_and_leaves_no_temporary(tmp_path):
    """The new content replaces the old one; only the destination is in the folder after."""
    path = tmp_path / "a.json"
    path.write_text("old")
    assert files.atomic_write_text(path, "new ü") == path
    assert path.read_text(encoding="utf-8") == "new ü"
    assert _listing(tmp_path) == ["a.json"]
    files.atomic_write_bytes(path, b"\x00\x01")
    assert path.read_bytes() == b"\x00\x01"


def test_permissions_are_those_of_a_plain_open(tmp_path):
    """The file gets 0o666 less the umask, not the 0o600 of a temporary file."""
    plain = tmp_path / "plain"
    plain.write_text("x")
    atomic = files.atomic_write_text(tmp_path / "atomic", "x")
    assert stat.S_IMODE(atomic.stat().st_mode) == stat.S_IMODE(plain.stat().st_mode)


@pytest.mark.parametrize("exception", [RuntimeError("disk"), KeyboardInterrupt()])
def test_interrupted_write_keeps_the_old_file_and_removes_the_temporary(
    tmp_path, monkeypatch, exception
):
    """An exception (Ctrl-C included) while writing leaves the old file whole, no temporary."""
    path = tmp_path / "a.json"
    path.write_text("old")
    seen = []

    def fail(fd):
        seen.append(_listing(tmp_path))  # the temporary exists at that moment
        raise exception

    monkeypatch.setattr(files.os, "fsync", fail)
    with pytest.raises(type(exception)):
        files.atomic_write_text(path, "new")
    assert path.read_text() == "old"
    assert _listing(tmp_path) == ["a.json"]
    assert len(seen[0]) == 2 and files.is_temporary(tmp_path / seen[0][0])


def test_atomic_path_renames_only_after_the_body(tmp_path):
    """A writer that takes a file name writes the temporary; a failing body changes nothing."""
    path = tmp_path / "fig.png"
    with files.atomic_path(path) as tmp:
        tmp.write_bytes(b"png")
        assert not path.exists() and tmp.parent == tmp_path
    assert path.read_bytes() == b"png"
    with pytest.raises(ValueError), files.atomic_path(path) as tmp:
        tmp.write_bytes(b"half")
        raise ValueError("plot failed")
    assert path.read_bytes() == b"png" and _listing(tmp_path) == ["fig.png"]


def test_clean_stale_temporaries_removes_only_temporaries(tmp_path):
    """Only files named .<name>.<random>.tmp go; gait files, hidden files and *.tmp stay."""
    keep = ["gait.json", ".hidden", "notes.tmp", ".x.tmp"]
    stale = [".gait.json.k3j_x9.tmp", ".fig4.png.abc.tmp"]
    for name in keep + stale:
        (tmp_path / name).write_text("1.2")
    (tmp_path / ".dir.json.x.tmp").mkdir()
    removed = files.clean_stale_temporaries(tmp_path)
    assert sorted(p.name for p in removed) == sorted(stale)
    assert _listing(tmp_path) == sorted([*keep, ".dir.json.x.tmp"])
    assert files.clean_stale_temporaries(tmp_path / "missing") == []


def test_temporary_names_are_recognised(tmp_path):
    """The helper's own temporary names are those clean_stale_temporaries removes."""
    with pytest.raises(KeyboardInterrupt), files.atomic_path(tmp_path / "a.json") as tmp:
        assert files.is_temporary(tmp)
        raise KeyboardInterrupt
    assert not tmp.exists()


def test_gait_file_with_nan_writes_nothing(tmp_path):
    """A gait file that cannot be valid JSON (NaN) is refused before any file appears."""
    with pytest.raises(ValueError):
        gait_file.write_json(tmp_path / "sub" / "g.json", {"speed": float("nan")})
    assert _listing(tmp_path / "sub") == []
    assert gait_file.write_json(tmp_path / "sub" / "g.json", {"speed": 0.3}).exists()


def test_a_fifo_is_refused_and_left_as_it_is(tmp_path):
    """A destination that is no regular file (a FIFO here, /dev/null on a system) is refused by
    name: a rename would replace it by a regular file. A regular file beside it is written."""
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    with pytest.raises(BipedError, match="'.*pipe'.*a device, a FIFO or a socket"):
        files.atomic_write_text(fifo, "x")
    assert stat.S_ISFIFO(fifo.stat().st_mode)
    assert _listing(tmp_path) == ["pipe"]
    files.atomic_write_text(tmp_path / "plain", "x")
    assert (tmp_path / "plain").read_text() == "x"


def test_a_symbolic_link_is_refused_and_left_as_it_is(tmp_path):
    """A destination that is a symbolic link (/dev/stdout is one) is refused: the rename
    would replace the link, not write through it. Its target is left as it was."""
    target = tmp_path / "target"
    target.write_text("old")
    link = tmp_path / "link"
    link.symlink_to(target)
    with pytest.raises(BipedError, match="'.*link'.*a symbolic link"):
        files.atomic_write_text(link, "x")
    assert link.is_symlink() and target.read_text() == "old"
