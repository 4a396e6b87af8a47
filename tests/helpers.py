"""Helpers shared by tests: run the ``bcfem`` command line on MPI ranks; closed forms used twice."""

import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import cores
import numpy as np
from scipy.optimize import brentq

BIN = Path(sys.executable).parent


def on_ranks(cmd: list[str], ranks: int) -> list[str]:
    """``cmd`` under ``mpirun -n ranks`` if ranks > 1; the test then holds every core until it
    ends (``tests/cores.py``)."""
    if ranks == 1:
        return cmd
    cores.take_all()
    return [str(BIN / "mpirun"), "-n", str(ranks), *cmd]


def rows_on_disk(out) -> list[dict]:
    """The rows of ``out/branch.csv`` (none if it is not there)."""
    from bcfem import io

    return io.read_csv(out / "branch.csv") if (out / "branch.csv").exists() else []


def killed(args, out, after: int, ranks: int = 1, rank: int | None = None) -> int:
    """Run ``bcfem ARGS --out out`` and SIGKILL it (all its ranks, or only ``rank``) once
    ``branch.csv`` holds ``after`` rows; returns the rows on disk then."""
    from test_run_contract import rank_pids

    cmd = on_ranks([str(BIN / "bcfem"), *map(str, args), "--out", str(out)], ranks)
    env = {**os.environ, "PATH": f"{BIN}{os.pathsep}{os.environ['PATH']}"}
    process = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)
    deadline = time.monotonic() + 300
    while len(rows_on_disk(out)) < after:
        assert process.poll() is None and time.monotonic() < deadline, "the run ended before it was killed"
        time.sleep(0.01)
    if ranks == 1:
        process.kill()
    else:
        pids = rank_pids(process.pid)
        for r in (pids if rank is None else [rank]):
            os.kill(pids[r], signal.SIGKILL)
    process.wait(timeout=120)
    return len(rows_on_disk(out))


def bcfem(*args, ranks: int = 1, timeout: float = 600, env: dict | None = None) -> subprocess.CompletedProcess:
    """``bcfem ARGS`` (under ``mpirun -n ranks`` if ranks > 1), with the venv's bin on PATH and
    ``env`` added to the environment."""
    cmd = on_ranks([str(BIN / "bcfem"), *map(str, args)], ranks)
    full = {**os.environ, "PATH": f"{BIN}{os.pathsep}{os.environ['PATH']}", **(env or {})}
    return subprocess.run(cmd, capture_output=True, text=True, env=full, timeout=timeout)


def serial_and_parallel(out, *args) -> tuple[dict, dict]:
    """The ``summary.json`` of ``bcfem ARGS`` run serially and under ``mpirun -n 2``, each into its
    own directory under ``out``; either failing fails the test."""
    import json

    summaries = []
    for ranks in (1, 2):
        done = bcfem(*args, "--out", out / f"n{ranks}", ranks=ranks)
        assert done.returncode == 0, done.stderr
        summaries.append(json.loads((out / f"n{ranks}" / "summary.json").read_text()))
    return summaries[0], summaries[1]


def exact_uniaxial(stretch, kappa):
    """(lateral stretch l, nominal stress) of uniaxial stress in W = (I1-3)/2 - ln J + p(J-1)
    - p^2/(2 kappa), mu = 1, p = kappa (J - 1): l makes the lateral stress vanish."""

    def lateral_stress(l):
        J = stretch * l * l
        return l - 1 / l + kappa * (J - 1) * J / l

    l = brentq(lateral_stress, 0.2, 3.0, xtol=1e-15)
    J = stretch * l * l
    return l, stretch - 1 / stretch + kappa * (J - 1) * J / stretch


def exact_nominal_stress(stretch, kappa):
    """The nominal stress of :func:`exact_uniaxial`."""
    return exact_uniaxial(stretch, kappa)[1]


def same_loads(rows, reference, load: str, rtol: float = 1e-9) -> list[tuple[dict, dict]]:
    """The pairs (row, reference row) of one stage at the same ``load`` (``eps``, or the arc
    length ``s``). Two runs that differ in round-off (ranks, BLAS kernels) can differ in a Newton
    iteration count, which sizes the next arc-length step or cuts a load step: their rows meet
    at the declared checkpoints, and everywhere until their steps part."""
    pairs = []
    for row in rows:
        match = next((r for r in reference if r.get("stage") == row.get("stage")
                      and math.isclose(r[load], row[load], rel_tol=rtol, abs_tol=1e-12)), None)
        if match is not None:
            pairs.append((row, match))
    return pairs


def refused(*args, out) -> str:
    """``bcfem ARGS --out OUT`` run in this process, as bad input: it must exit 2 with one line
    on stderr and write nothing at ``out``. Returns that line. (A process per bad value would
    spend 0.6 s starting up; test_cli starts one for the unknown scene.)"""
    import contextlib
    import io

    import pytest

    from bcfem import cli
    stderr = io.StringIO()
    with contextlib.redirect_stderr(stderr), contextlib.redirect_stdout(io.StringIO()):
        with pytest.raises(SystemExit) as exit_:
            cli.main([*map(str, args), "--out", str(out)])
    lines = stderr.getvalue().splitlines()
    assert exit_.value.code == 2, (args, lines)
    assert len(lines) == 1, (args, lines)
    assert not Path(out).exists() or not any(Path(out).iterdir()), args
    return lines[0]


# -- Taylor tests through a problem ----------------------------------------------------------
# -- Taylor tests through the problem --------------------------------------------------------
def taylor(problem, energy, dx, eps0=1e-2, halvings=4, observe=None):
    """Taylor remainders of the assembled residual F and tangent J of ``problem`` at its
    current states x0, along the blocked vector ``dx``:

        |E(x0 + e dx) - E(x0) - e F(x0).dx|   and   ||F(x0 + e dx) - F(x0) - e J(x0) dx||

    for e = eps0, eps0/2, ... (``energy()``: the scaled energy at the states the problem's
    functions hold). ``observe()``, if given, is called at every e (e.g. the active set).
    The states are restored. Returns a dict of the remainders, of numbers that do not
    depend on the rank count, and of this rank's part of F(x0) (``residual``)."""
    x0 = problem.vector_from(problem.states)
    f0, f, x, jdx = (problem.new_vector() for _ in range(4))
    try:
        problem.snes.computeFunction(x0, f0)
        E0 = energy()
        A, _ = problem.jacobian()
        A.mult(dx, jdx)
        dE = f0.dot(dx)
        seen, energy_remainders, residual_remainders = [], [], []
        for k in range(halvings):
            eps = eps0 * 0.5**k
            x.waxpy(eps, dx, x0)
            problem.snes.computeFunction(x, f)  # also puts x into the states
            energy_remainders.append(abs(energy() - E0 - eps * dE))
            f.axpy(-1.0, f0)
            f.axpy(-eps, jdx)
            residual_remainders.append(f.norm())
            if observe is not None:
                seen.append(observe())
        problem.functions_from(x0, problem.states)
        return {"energy": E0, "dE": dE, "F": f0.norm(), "Jdx": jdx.norm(), "eps0": eps0,
                "energy_remainders": energy_remainders, "residual_remainders": residual_remainders,
                "seen": seen, "residual": f0.array.copy()}
    finally:
        for v in (x0, f0, f, x, jdx):
            v.destroy()


def rate(remainders, size):
    """The observed rates of convergence of the remainders; None when all of them are at
    round-off relative to ``size`` (a linear residual has a zero tangent remainder)."""
    r = np.asarray(remainders)
    if r.max() <= 1e-11 * size:
        return None
    return np.log2(r[:-1] / r[1:])


def assert_second_order(result, tol=0.05, linear=False):
    """Both remainders fall like e^2 (or the tangent's is round-off: a linear residual). A
    ``linear`` energy has both remainders at round-off: its residual is exact."""
    e_rates = rate(result["energy_remainders"], abs(result["energy"]) + result["eps0"] * abs(result["dE"]))
    f_rates = rate(result["residual_remainders"], result["F"] + result["eps0"] * result["Jdx"])
    if linear:
        assert e_rates is None and f_rates is None and result["F"] > 0, (e_rates, f_rates)
        return e_rates, f_rates
    assert e_rates is not None and np.all(np.abs(e_rates - 2) < tol), e_rates
    assert f_rates is None or np.all(np.abs(f_rates - 2) < tol), f_rates
    return e_rates, f_rates
