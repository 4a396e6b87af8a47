"""The hemisphere's closure under each difference between bcfem's model and the dissertation's
(issue 39): docs/benchmarks/crater-closure.{csv,md}.

Every variant is `bcfem run crater --preload closure` with one or two things changed: the bottom
face in frictionless contact (`--bottom contact`), no self-contact, no regulariser, the coarse
mesh, and a wall that may pass through the plate (a research-script model, below: the crater's
contact bounds left out). A variant whose path fails is a result: its last converged preload is
reported. The dissertation: eps_m = 0.47 (section 7.2.4).

Run from the repository root: `.venv/bin/python benchmarks/crater_closure.py [NAME ...]`
(names: the variants' keys; none: all of them, about 20 min on one core).
"""

from __future__ import annotations

import sys
import time

from mpi4py import MPI

from common import ROOT, atomic_text, csv_text

import bcfem  # noqa: F401  (before dolfinx / petsc4py)
from bcfem.io import read_csv
from bcfem.log import configure
from bcfem.runner import SolveError
from bcfem.scenes import crater
from bcfem.scenes.crater.model import Crater

OUT = ROOT / "docs" / "benchmarks"
DISSERTATION_EPS_M = 0.47


class WallThroughPlate(Crater):
    """The crater with no contact bounds: its wall (and a bottom face in contact) may pass
    through the plate, as a model without wall-plate contact would let it."""

    def contact_bounds(self, problem):
        pass


#: name -> (what changes, parameters, model class)
VARIANTS = {
    "default": ("bcfem's default: bottom held, self-contact, gamma/(mu a) = 0.01, size_crater 0.06", {}, None),
    "bottom-contact": ("the bottom face in frictionless contact", {"bottom": "contact"}, None),
    "no-self-contact": ("no self-contact", {"self_contact": 0.0}, None),
    "no-regulariser": ("no regulariser", {"surface_energy": 0.0}, None),
    "coarse": ("coarse mesh", {"size_crater": 0.16}, None),
    # a wall through the plate snaps again and again: six snaps a stage bound the run
    "wall-through-plate": ("the wall may pass through the plate", {"max_snaps": 6}, WallThroughPlate),
    "wall-through-plate-and-itself": ("the wall may pass through the plate and itself",
                                      {"self_contact": 0.0, "max_snaps": 6}, WallThroughPlate),
}
COLUMNS = ["variant", "change", "status", "eps_m", "F_tilde", "last_eps", "wall_time_s", "error"]


def closure(name: str) -> dict:
    change, changes, model_class = VARIANTS[name]
    params = crater.Params(preload=crater.PRELOAD_TO_CLOSURE, **changes)
    t0 = time.perf_counter()
    try:
        rows, summary = crater.solve(params, MPI.COMM_SELF, model_class)
        error = ""
    except SolveError as failure:
        rows, summary, error = failure.run.rows, failure.run.summary, str(failure)
    loading = [r for r in rows if r["stage"] == "load"]
    return {"variant": name, "change": change, "status": "failed" if error else "ok",
            "eps_m": summary.get("eps_m"), "F_tilde": summary.get("F_tilde"),
            "last_eps": loading[-1]["eps"] if loading else None,
            "wall_time_s": time.perf_counter() - t0, "error": error[:200]}


def markdown(rows: list[dict]) -> str:
    lines = ["# The hemisphere's closure against the dissertation's model",
             "",
             "`.venv/bin/python benchmarks/crater_closure.py`: each row is `bcfem run crater --preload closure`",
             f"with one change (the dissertation: eps_m = {DISSERTATION_EPS_M}). eps_m: V1 <= 1e-3 V0 on the",
             "stable path; F~ after unloading; a failed path gives its last converged preload.",
             "",
             "| variant | eps_m | against 0.47 | F~ | status | wall time [s] |",
             "|---|---|---|---|---|---|"]
    for r in rows:
        eps = r["eps_m"]
        gap = f"{100 * (float(eps) / DISSERTATION_EPS_M - 1):+.1f} %" if eps not in (None, "") else "—"
        shown = f"{float(eps):.4f}" if eps not in (None, "") else f"— (last {float(r['last_eps']):.4f})"
        force = f"{float(r['F_tilde']):.3f}" if r["F_tilde"] not in (None, "") else "—"
        lines.append(f"| {r['change']} | {shown} | {gap} | {force} | {r['status']} | {float(r['wall_time_s']):.0f} |")
    return "\n".join(lines) + "\n"


def main(names: list[str]) -> None:
    configure(MPI.COMM_SELF, quiet=False)  # the progress line of each run
    path = OUT / "crater-closure.csv"
    kept = {r["variant"]: r for r in read_csv(path)} if path.exists() else {}
    for name in names or list(VARIANTS):
        kept[name] = closure(name)
        print(f"{name}: {kept[name]['status']}, eps_m {kept[name]['eps_m']}", flush=True)
        rows = [kept[n] for n in VARIANTS if n in kept]  # written as each variant ends
        atomic_text(path, csv_text(rows, COLUMNS))
        atomic_text(OUT / "crater-closure.md", markdown(rows))


if __name__ == "__main__":
    main(sys.argv[1:])
