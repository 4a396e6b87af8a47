"""FGMRES iterations per Newton step under the displacement–pressure split, on the wedges of
crater-sector's drawn study: the quarter (m = 2, both mirrors held by a component) against the
wedges pi/4 and pi/8, whose oblique mirror is a multiplier field (docs/three-dimensional.md,
"stability without a factorisation"). Each wedge runs the drawn study's first two steps in a
subprocess with the split's options and ``ksp_converged_reason``; the script prints the
iterations of every Newton step. Run from the repository root, e.g.

    .venv/bin/python benchmarks/sector_split.py --layer-stiffness 1

(about 2 min on one core).
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys

ONE_WEDGE = """
import bcfem  # noqa: F401
from petsc4py import PETSc
from bcfem.geometry.crater_sector import CraterSector
from bcfem.scenes.crater_sector import drawn_stability
from bcfem.solver.fieldsplit import SCHUR_GAMG
options = PETSc.Options()
prefix = "bcfem_crater_sector_drawn_1_"
for key, value in {{**SCHUR_GAMG, "ksp_converged_reason": None}}.items():
    options[prefix + key] = value
drawn_stability([0.01, 0.02], layer_stiffness={stiffness},
                sector=CraterSector(size_wall=0.1, layer_thickness=0.05, wedge_waves={m}))
"""


def iterations(m: int, stiffness: float) -> list[int]:
    """FGMRES iterations of every Newton step of the wedge pi/m's first two drawn steps."""
    out = subprocess.run([sys.executable, "-c", ONE_WEDGE.format(m=m, stiffness=stiffness)],
                         capture_output=True, text=True, check=True).stdout
    return [int(n) for n in re.findall(r"solve converged due to \w+ iterations (\d+)", out)]


if __name__ == "__main__":
    cli = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    cli.add_argument("--layer-stiffness", type=float, default=1.0, help="the coating's modulus over the specimen's")
    cli.add_argument("--waves", type=int, nargs="+", default=[2, 4, 8], help="wedges pi/m")
    args = cli.parse_args()
    for m in args.waves:
        its = iterations(m, args.layer_stiffness)
        print(f"m = {m}: {len(its)} Newton steps, FGMRES iterations {min(its)}-{max(its)}: {its}", flush=True)
