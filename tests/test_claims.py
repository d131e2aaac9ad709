"""One run at a time on an output (``biped.runtime.claims``): a second run on a claimed file or
folder, or on a file inside a claimed folder, is refused before any work; two files of one
folder are two outputs; a claim ends with its process, however it ends."""

import contextlib
import io
import os
import signal
import subprocess
import sys
import time

import pytest

import biped
from biped.runtime import claims
from biped.runtime.claims import claimed
from biped.studies.sweep import run_sweep, sweep_settings
from tests.background import PROGRAM

# A process that claims the path of its first argument and holds it until killed.
_HOLDER = """
import sys, time
from biped.runtime.claims import claimed
with claimed(sys.argv[1]):
    print("held", flush=True)
    time.sleep(600)
"""

pytestmark = pytest.mark.skipif(claims.fcntl is None, reason="no claims without fcntl")


@contextlib.contextmanager
def held_elsewhere(path, kill=signal.SIGTERM):
    """``path`` claimed by another process within the block; that process killed by ``kill``
    after it."""
    holder = subprocess.Popen(
        [sys.executable, "-c", _HOLDER, str(path)], stdout=subprocess.PIPE, text=True
    )
    try:
        assert holder.stdout.readline().strip() == "held"
        yield holder
    finally:
        holder.send_signal(kill)
        holder.wait(timeout=30)


def test_a_claimed_output_is_refused_to_another_run_until_its_holder_ends(tmp_path):
    """A folder held by another process is refused with the holder named, and so is a file
    inside it; a folder beside it is free. Once the holder is killed outright (SIGKILL), the
    folder is free again."""
    folder = tmp_path / "sweep"
    with held_elsewhere(folder, kill=signal.SIGKILL) as holder:
        for path in (folder, folder / "rolling-sthenic-0.300.json"):
            with pytest.raises(biped.BipedError) as refused, claimed(path):
                pass
            assert f"pid {holder.pid}" in str(refused.value)
            assert "in use by another run" in str(refused.value)
        with claimed(tmp_path / "other"):
            pass
        assert not folder.exists()  # a refused claim writes nothing there
    with claimed(folder):
        pass


def test_a_file_claimed_keeps_its_folder_from_a_run_but_not_its_neighbour(tmp_path):
    """A file held by another process: its folder cannot be claimed (a sweep there would write
    over it), a file beside it can."""
    with held_elsewhere(tmp_path / "out" / "a.rrd"):
        with (
            pytest.raises(biped.BipedError, match="in use by another run"),
            claimed(tmp_path / "out"),
        ):
            pass
        with claimed(tmp_path / "out" / "b.rrd"):
            pass


def test_a_process_claims_what_it_holds_again_and_within_it(tmp_path):
    """Within one process, a folder claimed (a command's output) can be claimed again (its
    campaign) and a file within it too; each is released with its block."""
    folder = tmp_path / "folder"
    with claimed(folder):
        with claimed(folder), claimed(folder / "file.json"):
            pass
        assert str(folder) in claims._held
    assert not [p for p in claims._held if p.startswith(str(tmp_path))]


def test_a_sweep_on_a_folder_in_use_is_refused_and_writes_nothing(tmp_path):
    """run_sweep on a folder another run holds raises before anything is written."""
    settings = sweep_settings(biped.Robot.paper(), [0.3], starts=1)
    with held_elsewhere(tmp_path / "sweep"):
        with pytest.raises(biped.BipedError, match="in use by another run"):
            run_sweep(tmp_path / "sweep", settings, knees=("revolute",), stream=io.StringIO())
    assert not (tmp_path / "sweep").exists()


def _biped(*argv, **kwargs):
    return subprocess.run(
        [sys.executable, "-c", PROGRAM, *map(str, argv)],
        capture_output=True,
        text=True,
        timeout=300,
        **kwargs,
    )


def test_two_sweeps_on_one_folder_at_once_the_second_is_refused(tmp_path):
    """Two `biped sweep --out X` at once, the second with another clearance: it exits 2 with one
    line naming the folder and the first run, writing nothing; the first ends as alone
    (exit 0), its record and its gait files of one clearance."""
    out = tmp_path / "sweep"
    argv = ["sweep", "--speeds", "0.3", "--knees", "revolute", "--criteria", "sthenic"]
    argv += ["--starts", "1", "--paper-seeds", "0", "--jobs", "1", "--out", str(out)]
    first = subprocess.Popen(
        [sys.executable, "-c", PROGRAM, *argv],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        deadline = time.monotonic() + 120
        while not (out / "sweep.json").exists():
            assert first.poll() is None and time.monotonic() < deadline
            time.sleep(0.05)
        # the first run held still while the second starts: it cannot finish first (a
        # quick sweep on a loaded machine did), and it still holds its claim
        os.kill(first.pid, signal.SIGSTOP)
        try:
            second = _biped(*argv, "--clearance", "0.01")
        finally:
            os.kill(first.pid, signal.SIGCONT)
        _, err = first.communicate(timeout=300)
    finally:
        if first.poll() is None:
            first.kill()
    assert second.returncode == 2, second.stderr
    (line,) = second.stderr.splitlines()
    assert f"--out {str(out)!r} is in use by another run (pid {first.pid}" in line
    assert first.returncode == 0, err
    assert '"clearance": 0.0' in (out / "sweep.json").read_text()


def _refused(done, command: str, option: str, path) -> None:
    """Exit 2 and one line naming the option, the path and the run holding it."""
    assert done.returncode == 2, done.stderr
    (line,) = done.stderr.splitlines()
    assert line.startswith(f"biped {command}: error: {option} {str(path)!r} is in use by ")
    assert line.endswith(
        "allowed one run at a time on an output; wait for it to end or choose another path"
    )


def test_an_output_file_in_use_is_refused_before_any_work(tmp_path):
    """`biped optimize --out F` and `biped validate G --rrd F` while another run holds F: exit
    2, one line naming the option and the file, nothing written; F free, they run."""
    gait, rrd = tmp_path / "gait.json", tmp_path / "walk.rrd"
    optimize = ["optimize", "--knee", "rolling", "--speed", "0.3", "--starts", "1", "--out"]
    with held_elsewhere(gait):
        _refused(_biped(*optimize, gait), "optimize", "--out", gait)
    assert not gait.exists()
    assert _biped(*optimize, gait).returncode == 0
    with held_elsewhere(rrd):
        _refused(_biped("validate", gait, "--rrd", rrd), "validate", "--rrd", rrd)
    assert not rrd.exists()
