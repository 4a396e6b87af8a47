"""Helpers shared by tests: run the ``bcfem`` command line on MPI ranks; closed forms used twice."""

import math
import os
import subprocess
import sys
from pathlib import Path

from scipy.optimize import brentq

BIN = Path(sys.executable).parent


def bcfem(*args, ranks: int = 1, timeout: float = 600, env: dict | None = None) -> subprocess.CompletedProcess:
    """``bcfem ARGS`` (under ``mpirun -n ranks`` if ranks > 1), with the venv's bin on PATH and
    ``env`` added to the environment."""
    cmd = [str(BIN / "bcfem"), *map(str, args)]
    if ranks > 1:
        cmd = [str(BIN / "mpirun"), "-n", str(ranks), *cmd]
    full = {**os.environ, "PATH": f"{BIN}{os.pathsep}{os.environ['PATH']}", **(env or {})}
    return subprocess.run(cmd, capture_output=True, text=True, env=full, timeout=timeout)


def exact_nominal_stress(stretch, kappa):
    """Uniaxial stress of W = (I1-3)/2 - ln J + p(J-1) - p^2/(2 kappa), mu = 1, p = kappa (J - 1):
    the lateral stretch l makes the lateral stress vanish."""

    def lateral_stress(l):
        J = stretch * l * l
        return l - 1 / l + kappa * (J - 1) * J / l

    l = brentq(lateral_stress, 0.2, 3.0, xtol=1e-15)
    J = stretch * l * l
    return stretch - 1 / stretch + kappa * (J - 1) * J / stretch


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
