"""Ctrl-C and SIGTERM during an IPOPT solve stop the program: CasADi stops the solver when a
signal's handler raises but swallows the exception (``biped.runtime.interrupts`` raises it again),
and its notice of the swallowed exception stays off the terminal."""

import contextlib
import io
import os
import signal
import sys
import threading

import pytest

import biped
from biped.optimization.problem import GaitProblem
from biped.optimization.solver import Solver, solver_for
from biped.runtime import runner
from biped.runtime.interrupts import kept_interrupts
from biped_cli import main
from tests.background import PROMPTLY, stop_while_workers_run

# CasADi's notice, in the pieces it writes.
NOTICE = ("CasADi - ", "2026-01-01", ' WARNING("', "KeyboardInterruptException", '") [', "x.cpp]\n")


@pytest.fixture(autouse=True)
def ctrl_c():
    """Ctrl-C raises KeyboardInterrupt in this process, as in a terminal (a shell's background
    job inherits it ignored)."""
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, previous)


class Stopped(BaseException):
    """A handler's exception, as the command line's ``Terminated``."""


def swallowing_solver(signum):
    """What CasADi does: the signal's handler raises inside, the solver catches it, writes
    its notice in pieces and returns a status."""
    try:
        os.kill(os.getpid(), signum)
        for _ in range(1000):  # the handler runs between two bytecodes
            pass
    except BaseException:
        for piece in NOTICE:
            sys.stderr.write(piece)
        return "NonIpopt_Exception_Thrown"
    return "Solve_Succeeded"


def test_a_swallowed_interrupt_is_raised_again(monkeypatch):
    """Without the guard the interrupt is lost (the solver returns a status); with it, the
    handler's own exception goes up after the solver returns, and CasADi's notice is not
    written (other lines on stderr are)."""
    assert swallowing_solver(signal.SIGINT) == "NonIpopt_Exception_Thrown"
    err = io.StringIO()
    monkeypatch.setattr(sys, "stderr", err)
    with pytest.raises(KeyboardInterrupt), kept_interrupts():
        sys.stderr.write("a line of our own\n")
        swallowing_solver(signal.SIGINT)
    assert err.getvalue() == "a line of our own\n"

    def stop(signum, frame):
        raise Stopped

    previous = signal.signal(signal.SIGTERM, stop)
    try:
        with pytest.raises(Stopped), kept_interrupts():
            swallowing_solver(signal.SIGTERM)
    finally:
        signal.signal(signal.SIGTERM, previous)
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_a_handler_that_returns_lets_the_solver_go_on():
    """A handler that does not raise (it only takes note) stops nothing."""
    noted = []
    previous = signal.signal(signal.SIGTERM, lambda *_: noted.append(1))
    try:
        with kept_interrupts():
            assert swallowing_solver(signal.SIGTERM) == "Solve_Succeeded"
    finally:
        signal.signal(signal.SIGTERM, previous)
    assert noted == [1]


def test_ctrl_c_stops_a_real_ipopt_solve(capfd):
    """Ctrl-C 50 ms into IPOPT's solve (about a second from the first guess) raises
    KeyboardInterrupt when the solver returns; nothing of CasADi's on stderr."""
    problem = GaitProblem(biped.Biped(biped.Robot.paper(), "rolling"), 0.3)
    solver = solver_for(problem)
    capfd.readouterr()
    timer = threading.Timer(0.05, os.kill, (os.getpid(), signal.SIGINT))
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        solver.solve(problem, problem.first_guess())
    timer.join()
    assert "CasADi" not in capfd.readouterr().err


def test_ctrl_c_while_casadi_builds_the_graph_is_not_lost(monkeypatch):
    """CasADi asks Python for each operand's shape while it builds the step's graph, and
    swallows an exception raised there: a Ctrl-C whose handler runs at that moment (a sweep
    worker's SIGTERM did, and the pool never ended) is lost without the guard, raised with it."""
    import casadi as ca

    shape = ca.SX.shape
    calls = {"n": 0, "at": None}

    def shape_then_ctrl_c(self):
        calls["n"] += 1
        if calls["n"] == calls["at"]:
            signal.raise_signal(signal.SIGINT)  # the handler runs inside this call
        return shape.fget(self)

    monkeypatch.setattr(ca.SX, "shape", property(shape_then_ctrl_c))
    model = biped.Biped(biped.Robot.paper(), "revolute")
    Solver(model, "sthenic", GaitProblem(model, 0.3).safety, 4)
    whole, calls["n"], calls["at"] = calls["n"], 0, 20  # a whole build's calls
    assert whole > calls["at"] + 100
    with pytest.raises(KeyboardInterrupt):
        Solver(model, "sthenic", GaitProblem(model, 0.3).safety, 4)
    assert calls["n"] == whole  # the build went on to its end past the interrupt: swallowed
    calls["n"], calls["at"] = 0, 20  # and the same without the guard: lost
    monkeypatch.setattr("biped.optimization.solver.kept_interrupts", _no_guard)
    Solver(model, "sthenic", GaitProblem(model, 0.3).safety, 4)  # no KeyboardInterrupt
    assert calls["n"] == whole  # the handler ran (at call 20): its exception lost


@contextlib.contextmanager
def _no_guard():
    yield


@pytest.mark.parametrize("cores", [1, 2])
@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_biped_optimize_stops_at_a_signal_during_the_solve(
    signum, cores, tmp_path, capsys, monkeypatch
):
    """`biped optimize` signalled 50 ms into its first IPOPT solve exits 130 / 143 with one
    line, writing nothing (the interrupt lost, it would go on to its other starts and write
    the gait): with its starts solved in this process (1 core) or in forked workers (2), where
    the solve runs in a worker and the signal goes to the command's process."""
    solve = Solver.solve
    signalled = []
    command = os.getpid()
    monkeypatch.setattr("biped.optimization.optimize.free_cores", lambda: cores)

    def solve_and_signal(self, *args, **kwargs):
        if not signalled:
            signalled.append(threading.Timer(0.05, os.kill, (command, signum)))
            signalled[0].start()
        return solve(self, *args, **kwargs)

    monkeypatch.setattr(Solver, "solve", solve_and_signal)
    out = tmp_path / "gait.json"
    argv = ["optimize", "--knee", "rolling", "--speed", "0.3", "--starts", "3"]
    # A lost signal hangs: pytest's faulthandler_timeout (pyproject) ends the test run then.
    assert main([*argv, "--out", str(out)]) == 128 + signum
    for timer in signalled:  # (none here when the solve ran in a worker)
        timer.join()
    name = {signal.SIGINT: "Ctrl-C", signal.SIGTERM: "SIGTERM"}[signum]
    assert capsys.readouterr().err.splitlines()[-1] == f"biped optimize: interrupted ({name})"
    assert not list(tmp_path.iterdir())


@pytest.mark.skipif(runner.free_cores() < 2, reason="the starts are forked on 2 cores or more")
@pytest.mark.parametrize(
    "signum, to_group", [(signal.SIGINT, True), (signal.SIGINT, False), (signal.SIGTERM, False)]
)
def test_a_background_optimize_stops_while_its_starts_run_in_workers(signum, to_group, tmp_path):
    """`biped optimize --criterion energy` started as a script's background job (Ctrl-C
    ignored: it ran on to write its file and exit 0), signalled while its starts run in
    forked worker processes: Ctrl-C to its process group as a terminal sends it, or to its
    process alone, and SIGTERM, stop it and its workers within seconds, 130 / 143 and one
    line, writing nothing."""
    out = tmp_path / "gait.json"
    argv = ["optimize", "--knee", "rolling", "--speed", "0.3", "--criterion", "energy"]
    stopped = stop_while_workers_run([*argv, "--out", str(out)], signum, to_group)
    name = {signal.SIGINT: "Ctrl-C", signal.SIGTERM: "SIGTERM"}[signum]
    assert stopped.status == 128 + signum, stopped.stderr
    assert stopped.stderr.splitlines()[-1] == f"biped optimize: interrupted ({name})"
    assert "Traceback" not in stopped.stderr
    assert stopped.seconds < PROMPTLY
    assert not list(tmp_path.iterdir())
