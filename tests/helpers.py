"""Helpers shared by tests: run the ``bcfem`` command line on one or more MPI ranks."""

import os
import subprocess
import sys
from pathlib import Path

BIN = Path(sys.executable).parent


def bcfem(*args, ranks: int = 1, timeout: float = 600) -> subprocess.CompletedProcess:
    """``bcfem ARGS`` (under ``mpirun -n ranks`` if ranks > 1), with the venv's bin on PATH."""
    cmd = [str(BIN / "bcfem"), *map(str, args)]
    if ranks > 1:
        cmd = [str(BIN / "mpirun"), "-n", str(ranks), *cmd]
    env = {**os.environ, "PATH": f"{BIN}{os.pathsep}{os.environ['PATH']}"}
    return subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=timeout)
