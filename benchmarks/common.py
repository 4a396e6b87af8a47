"""What the benchmark scripts share: one-core worker processes, Newton counting,
Richardson extrapolation, atomic text output and table formatting."""

from __future__ import annotations

import csv
import io
import json
import math
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

from bcfem.path.roots import bracketed_root  # dolfinx-free

ROOT = Path(__file__).resolve().parents[1]


def run_worker(script: str, case: dict, core: str = "0", cache: str | None = None) -> dict:
    """Run ``script --worker CASE`` in a fresh process pinned to ``core`` (one thread);
    ``cache`` is an XDG_CACHE_HOME for cold-JIT runs. Returns its ``RESULT`` line plus
    the whole process time."""
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", MKL_NUM_THREADS="1")
    env.pop("PETSC_OPTIONS", None)
    if cache:
        env["XDG_CACHE_HOME"] = cache
    cmd = [sys.executable, script, "--worker", json.dumps(case)]
    if shutil.which("taskset"):
        cmd = ["taskset", "-c", core, *cmd]
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, env=env, capture_output=True, text=True, cwd=ROOT)
    t_process = time.perf_counter() - t0
    lines = [ln for ln in proc.stdout.splitlines() if ln.startswith("RESULT ")]
    if proc.returncode != 0 or not lines:
        raise RuntimeError(f"case {case} failed:\n{proc.stdout[-2000:]}\n{proc.stderr[-2000:]}")
    return {**json.loads(lines[-1][7:]), "t_process": t_process}


def mpirun_bcfem(args: list[str], ranks: int, quiet_stdout: bool = False) -> None:
    """Run ``mpirun -n RANKS bcfem ARGS`` from the repository's venv (the user's PETSC_OPTIONS
    left out, so that the kept results do not depend on them); raises if it fails."""
    bin_dir = ROOT / ".venv" / "bin"
    env = {**os.environ, "PATH": f"{bin_dir}:{os.environ['PATH']}"}
    env.pop("PETSC_OPTIONS", None)
    subprocess.run([str(bin_dir / "mpirun"), "-n", str(ranks), str(bin_dir / "bcfem"), *args], cwd=ROOT, env=env,
                   check=True, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL if quiet_stdout else None)


def count_newton():
    """Count every Newton solve and iteration from now on (also those of event location and
    Brent; ``Branch.newton_iterations`` counts accepted steps only).

    Returns:
        (the running counts, a function that stops counting)
    """
    from bcfem.solver.problem import Problem

    count = {"solves": 0, "its": 0}
    solve = Problem.solve

    def counted(self, *args, **kwargs):
        ok = solve(self, *args, **kwargs)
        count["solves"] += 1
        count["its"] += self.iterations
        return ok

    Problem.solve = counted
    return count, lambda: setattr(Problem, "solve", solve)


def loadavg() -> str:
    """The 1-minute load average ("?" where /proc is missing): were other jobs running?"""
    p = Path("/proc/loadavg")
    return p.read_text().split()[0] if p.exists() else "?"


def busy_cores(seconds: float = 3.0) -> float:
    """Cores kept busy by other processes over ``seconds`` (from /proc/stat; nan if unknown)."""
    def sample():
        fields = [float(x) for x in Path("/proc/stat").read_text().splitlines()[0].split()[1:]]
        return sum(fields), fields[3] + fields[4]  # total, idle + iowait

    try:
        t0, i0 = sample()
        time.sleep(seconds)
        t1, i1 = sample()
    except (OSError, ValueError, IndexError):
        return math.nan
    return (os.cpu_count() or 1) * (1 - (i1 - i0) / (t1 - t0))


def wait_idle(max_wait: float) -> tuple[float, float]:
    """Wait up to ``max_wait`` s for the machine to be idle (< 0.2 busy cores); returns
    (seconds waited, busy cores at the end)."""
    t0 = time.perf_counter()
    busy = busy_cores()
    while busy > 0.2 and time.perf_counter() - t0 < max_wait:
        time.sleep(10)
        busy = busy_cores()
    return time.perf_counter() - t0, busy


def richardson(coarse, fine, order):
    return fine + (fine - coarse) / (2**order - 1)


def fmt(x, spec=".2e"):
    return "" if x is None or (isinstance(x, float) and math.isnan(x)) else format(x, spec)


def csv_text(rows, columns) -> str:
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=columns, extrasaction="ignore", lineterminator="\n")
    w.writeheader()
    for r in rows:
        w.writerow({k: (repr(v) if isinstance(v, float) else v) for k, v in r.items()})
    return buf.getvalue()


def atomic_text(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp")
    tmp.write_text(text)
    os.replace(tmp, path)


def marks(name: str) -> tuple[str, str]:
    """The markers of a section that another script keeps in a shared markdown file."""
    return f"<!-- {name}:begin -->", f"<!-- {name}:end -->"


def put_section(path: Path, name: str, block: str) -> None:
    """Replace (or append) the marked section ``name`` of the markdown file ``path``;
    ``block`` holds no markers."""
    begin, end = marks(name)
    block = f"{begin}\n{block.strip()}\n{end}"
    text = path.read_text() if path.exists() else ""
    if begin in text:
        text = text[:text.index(begin)] + block + text[text.index(end) + len(end):]
    else:
        text = text.rstrip("\n") + "\n\n" + block + "\n"
    atomic_text(path, text)


def kept_sections(path: Path, names) -> str:
    """The marked sections ``names`` of ``path`` as they are (to carry over a regeneration)."""
    text = path.read_text() if path.exists() else ""
    parts = []
    for begin, end in map(marks, names):
        if begin in text:
            parts.append(text[text.index(begin):text.index(end) + len(end)])
    return "\n\n".join(parts)


def save_figure(fig, path: Path) -> None:
    """Save a driver's figure: the driver is one process, whatever ranks its runs used."""
    from mpi4py import MPI

    from bcfem import io as bcfem_io
    bcfem_io.save_figure(fig, path, MPI.COMM_SELF)


#: the finest meshes whose differences must keep their sign and shrink for Richardson
MONOTONE_MESHES = 4


def observed_order(h, q):
    """p with (q1 - q0)/(q2 - q1) = (h0^p - h1^p)/(h1^p - h2^p) (any mesh ratios), or None."""
    d0, d1 = q[1] - q[0], q[2] - q[1]
    if d0 == 0 or d1 == 0 or d0 * d1 < 0:
        return None
    f = lambda p: (h[0] ** p - h[1] ** p) / (h[1] ** p - h[2] ** p) - d0 / d1  # noqa: E731
    try:
        return bracketed_root(f, 0.05, 12.0, xtol=1e-12)
    except ValueError:
        return None


def reference(series, monotone_meshes: int = MONOTONE_MESHES):
    """The reference F~ of a crater's mesh sequence (rows with ``size_crater`` and ``F_tilde``,
    coarse to fine, ok runs only).

    Richardson extrapolation of the two finest meshes, with the order observed on the three
    finest, if the finest ``monotone_meshes`` values converge monotonically (their differences keep
    one sign and shrink in magnitude) and the order is in [0.5, 8]; else the finest mesh."""
    h = [r["size_crater"] for r in series]
    F = [r["F_tilde"] for r in series]
    d = [b - a for a, b in zip(F, F[1:])]
    tail = d[-(monotone_meshes - 1):]
    monotone = (len(tail) == monotone_meshes - 1 and all(x * tail[0] > 0 for x in tail)
                and all(abs(b) < abs(a) for a, b in zip(tail, tail[1:])))
    sign_changes = sum(1 for a, b in zip(d, d[1:]) if a * b < 0)
    ref = {"finest": series[-1]["size_crater"], "F_finest": F[-1], "monotone": monotone,
           "sign_changes": sign_changes, "differences": d, "meshes": len(series)}
    p = observed_order(h[-3:], F[-3:]) if len(F) >= 3 else None
    ref["order"] = p
    if monotone and p is not None and 0.5 <= p <= 8:
        r = h[-2] / h[-1]
        ref.update(F=F[-1] + (F[-1] - F[-2]) / (r**p - 1), kind="richardson",
                   meshes_used=(h[-2], h[-1]))
    else:
        ref.update(F=F[-1], kind="finest")
    return ref
