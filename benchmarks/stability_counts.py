"""Every stability count of a crater-cell run made twice: by the spectrum and by MUMPS's inertia.

Both counts see the same tangent with the same rows held; the run goes on with MUMPS's. The
script prints one line per count and a summary row (counts, how many equal, the totals, the
Davidson iterations per count) for docs/three-dimensional.md, and writes the counts to
``<out>/counts.json``. Run from the repository root, on an idle machine, e.g.

    .venv/bin/python benchmarks/stability_counts.py --filling 0.0490873852 --preload 0.0125 \\
        --fluid liquid --out /tmp/counts

(about 1 min on one core); any `bcfem run crater-cell` flag passes through (`--solver split`
is added: the spectrum takes the split).
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import bcfem  # noqa: F401  (before dolfinx / petsc4py)
import bcfem.stability.inertia as inertia
from bcfem.cli import main

counts: list[dict] = []
by_spectrum = inertia.spectrum_count


def both(problem, jacobian, rows):
    start = time.perf_counter()
    spectrum = by_spectrum(problem, jacobian, rows)
    middle = time.perf_counter()
    tangent = problem.kept("tangent_inertia", lambda: inertia.TangentInertia(problem.prefix + "inertia_"))
    mumps = tangent.negative(jacobian, rows)
    end = time.perf_counter()
    kept = problem.kept("tangent_spectrum", lambda: None)
    counts.append(dict(spectrum=spectrum, mumps=mumps, spectrum_s=middle - start, mumps_s=end - middle,
                       davidson=kept.iterations, krylov=kept.inner_iterations, lowest=kept.lowest))
    if problem.comm.rank == 0:
        print("count", counts[-1], flush=True)
    return mumps


def summary_row() -> str:
    equal = sum(c["spectrum"] == c["mumps"] for c in counts)
    return (f"| {len(counts)} | {equal} of {len(counts)} | {sum(c['spectrum_s'] for c in counts):.1f}; "
            f"{', '.join(str(c['davidson']) for c in counts)} | {sum(c['mumps_s'] for c in counts):.1f} |")


if __name__ == "__main__":
    argv = sys.argv[1:]
    out = Path(argv[argv.index("--out") + 1])
    inertia.spectrum_count = both
    try:
        main(["run", "crater-cell", *argv, "--solver", "split", "--stability", "spectrum", "--quiet",
              "--no-plots"])
    except SystemExit as code:
        if code.code not in (0, None):
            raise
    from mpi4py import MPI

    if MPI.COMM_WORLD.rank == 0:
        (out / "counts.json").write_text(json.dumps(counts, indent=1))
        print("| counts | equal | spectrum: total [s], Davidson iterations per count | MUMPS: total [s] |")
        print(summary_row())
