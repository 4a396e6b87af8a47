"""The hemisphere's closure under each difference between bcfem's model and the dissertation's
docs/benchmarks/crater-closure.{csv,md}.

Every variant is `bcfem run crater --preload closure` with one or more things changed: the bottom
face in frictionless contact, no self-contact, no regulariser, the mesh, the elements (Q1-P0 on
quadrilaterals, the analogue of Abaqus's CAX4H), the specimen's radius, and two research-script
models (below): a wall that may pass through the plate, and other closure definitions. Each
variant also gives eps_c, the dissertation's criterion of Fig. 7.6b: the preload whose
end-of-unloading pressure drop -dp reaches 0.83 p_a, interpolated linearly between cycles
0.025 apart. A variant whose path fails is a result: its last converged preload is reported.
The dissertation: eps_m = 0.47, eps_c = 0.43 (section 7.2.4).

Run from the repository root: `.venv/bin/python benchmarks/crater_closure.py [NAME ...]`
(names: the variants' keys; none: all of them, about 40 min on one core); `--render-only` renders
the .md again from the CSV (the report is `benchmarks/templates/crater-closure.md`).
"""

from __future__ import annotations

import sys
import time
from dataclasses import replace

from mpi4py import MPI

from common import ROOT, atomic_text, csv_text, render, table, write_report

import bcfem  # noqa: F401  (before dolfinx / petsc4py)
from bcfem.io import read_csv
from bcfem.log import configure
from bcfem.mpi import PointEvaluator
from bcfem.run.runner import SolveError
from bcfem.scenes import crater
from bcfem.scenes.crater.model import Crater

OUT = ROOT / "docs" / "benchmarks"
DISSERTATION = {"eps_m": 0.47, "eps_c": 0.43}
#: Fig. 7.6b's critical pressure drop over p_a, and the preloads eps_c is searched on
CRITICAL_DROP = 0.83
EPS_C_START, EPS_C_STEP = 0.35, 0.025
#: the apex counts as on the plate within this gap, over a
APEX_GAP = 1e-4


class WallThroughPlate(Crater):
    """The crater with no contact bounds: its wall (and a bottom face in contact) may pass
    through the plate, as a model without wall-plate contact would let it."""

    def contact_bounds(self, problem):
        pass


class ApexClosure(Crater):
    """Closure read as the apex (the crater's pole) touching the plate: a loading row counts
    as closed (its ``V`` reported 0) once the pole is within ``APEX_GAP`` a of the plate, and
    as open (``V`` at least V0) before; ``V_over_V0`` stays the true volume. (Past closure
    the pole of the default crater stays 2e-5 a above the plate with V ~ 1e-12 V0: the last
    dimple the wall's surface energy holds, so it never touches to 1e-6 a.)"""

    def __init__(self, params, comm):
        super().__init__(params, comm)
        self._pole = PointEvaluator(self.mesh, [0.0, self.geometry.crater_height]).expression(self.u[1])

    def observe(self, stage, eps, V1=None):
        row = super().observe(stage, eps, V1)
        if stage == "load":
            g = self.geometry
            touching = g.crater_height + float(self._pole()[0]) <= APEX_GAP * g.crater_radius
            row["V"] = 0.0 if touching else max(row["V"], g.crater_volume)
        return row


class ZeroVolumeClosure(Crater):
    """Closure read as V = 0 (to 1e-8 V0, bcfem's 'closed'), not V <= 1e-3 V0: a loading row
    counts as closed (its ``V`` reported 0) only then, and as open (``V`` at least V0) before."""

    def observe(self, stage, eps, V1=None):
        row = super().observe(stage, eps, V1)
        if stage == "load":
            V0 = self.geometry.crater_volume
            row["V"] = 0.0 if row["V"] <= crater.CLOSURE_CRITERIA.closed * V0 else max(row["V"], V0)
        return row


#: the dissertation's reading of its model as Abaqus had it: no surface energy (eq. 7.7), a
#: frictionless plate the bottom face may lift off, no self-contact defined
ABAQUS = {"element": "q1p0", "bottom": "contact", "surface_energy": 0.0, "self_contact": 0.0}
#: the section 25.40 mm wide: the specimen's diameter taken as the axisymmetric model's radius
WIDE = {"specimen_radius": 25.4}

#: the width study: the section's radius in crater radii a, its height scaled with it from the
#: dissertation's section (25.40 x 35.13 mm)
A, WIDTHS, HEIGHT_OVER_WIDTH = 6.35, (2, 4, 6, 8, 16), 35.13 / 25.40

#: name -> (what changes, parameters, model class or None, eps_c too)
VARIANTS = {
    "default": ("bcfem's default: P2-P1, bottom held, self-contact, gamma/(mu a) = 0.01, size_crater 0.06",
                {}, None, True),
    "bottom-contact": ("the bottom face in frictionless contact", {"bottom": "contact"}, None, True),
    "no-self-contact": ("no self-contact", {"self_contact": 0.0}, None, False),
    "no-regulariser": ("no regulariser", {"surface_energy": 0.0}, None, False),
    "coarse": ("coarse mesh", {"size_crater": 0.16}, None, True),
    "q1p0": ("Q1-P0 quadrilaterals (CAX4H-like)", {"element": "q1p0"}, None, True),
    "q1p0-coarse": ("Q1-P0, coarse mesh", {"element": "q1p0", "size_crater": 0.16}, None, True),
    "q1p0-fine": ("Q1-P0, fine mesh", {"element": "q1p0", "size_crater": 0.03}, None, True),
    "q1p0-abaqus": ("Q1-P0, bottom in contact, no regulariser, no self-contact", ABAQUS, None, True),
    "closure-apex": ("closure read as the apex touching the plate", {}, ApexClosure, False),
    "closure-zero-volume": ("closure read as V = 0 (1e-8 V0)", {}, ZeroVolumeClosure, False),
    # a wall through the plate snaps again and again: a budget of snaps bounds the run
    "wall-through-plate": ("the wall may pass through the plate", {"max_snaps": 6}, WallThroughPlate, False),
    "wall-through-plate-and-itself": ("the wall may pass through the plate and itself",
                                      {"self_contact": 0.0, "max_snaps": 6}, WallThroughPlate, False),
    "radius-25.4": ("specimen radius 25.40 mm (the diameter as the section's width)", WIDE, None, True),
    "radius-25.4-q1p0": ("specimen radius 25.40 mm, Q1-P0", {**WIDE, "element": "q1p0"}, None, True),
    "radius-25.4-abaqus": ("specimen radius 25.40 mm, Q1-P0, bottom in contact, no regulariser, "
                           "no self-contact", {**WIDE, **ABAQUS}, None, True),
    "radius-25.4-crater-12.7": ("specimen radius 25.40 mm and crater radius 12.70 mm (both diameters "
                                "as radii)", {**WIDE, "crater_radius": 12.7}, None, True),
    "radius-38.1": ("specimen radius 38.10 mm (6 a)", {"specimen_radius": 38.1}, None, True),
    "dissertation": ("--specimen dissertation: 25.40 mm (4 a), Q1-P0", {"specimen": "dissertation"}, None, True),
    **{f"width-{n}a{tag}": (f"width {n} a, height {HEIGHT_OVER_WIDTH:.4g} times it{label}",
                            {"specimen_radius": round(n * A, 4), "specimen_height": round(HEIGHT_OVER_WIDTH * n * A, 4), **extra},
                            None, True)
       for n in WIDTHS for tag, label, extra in (("", ", P2-P1", {}), ("-q1p0", ", Q1-P0", {"element": "q1p0"}))},
}
COLUMNS = ["variant", "change", "status", "eps_m", "F_tilde", "eps_c", "last_eps", "wall_time_s", "command",
           "error"]


def command(name: str) -> str:
    """The command that gives a variant's eps_m (a research-script model: this script)."""
    _, changes, model_class, _ = VARIANTS[name]
    if model_class is not None:
        return f"python benchmarks/crater_closure.py {name}"
    flags = " ".join(f"--{k.replace('_', '-')} {v:g}" if isinstance(v, float) else f"--{k.replace('_', '-')} {v}"
                     for k, v in changes.items())
    return f"bcfem run crater --preload closure {flags}".strip()


def cycle(params) -> tuple[list[dict], dict, str]:
    """One cycle of the scene's own model: (rows, summary, error or '')."""
    try:
        rows, summary = crater.solve(params, MPI.COMM_SELF)
        return rows, summary, ""
    except SolveError as failure:
        return failure.run.rows, failure.run.summary, str(failure)


def critical_preload(base) -> tuple[float | None, list[tuple[float, float]]]:
    """eps_c: where the end-of-unloading -dp/p_a crosses CRITICAL_DROP, linear between the
    cycles EPS_C_STEP apart that bracket it (searched up, or down, from EPS_C_START); and the
    (preload, -dp) pairs solved."""
    drops = []

    def drop(eps):
        _, summary, error = cycle(replace(base, preload=eps))
        value = None if error or summary.get("p2_over_pa") is None else 1 - summary["p2_over_pa"]
        drops.append((eps, value))
        return value

    eps, value = EPS_C_START, drop(EPS_C_START)
    step = EPS_C_STEP if value is not None and value < CRITICAL_DROP else -EPS_C_STEP
    while value is not None and 0 < eps + step < crater.MAX_CLOSURE_PRELOAD:
        previous = (eps, value)
        eps = round(eps + step, 10)
        value = drop(eps)
        if value is not None and (value - CRITICAL_DROP) * (previous[1] - CRITICAL_DROP) <= 0:
            (e0, d0), (e1, d1) = previous, (eps, value)
            return e0 + (CRITICAL_DROP - d0) * (e1 - e0) / (d1 - d0), drops
    return None, drops


def closure(name: str) -> dict:
    change, changes, model_class, with_eps_c = VARIANTS[name]
    params = crater.Params(preload=crater.PRELOAD_TO_CLOSURE, **changes)
    t0 = time.perf_counter()
    try:
        rows, summary = crater.solve(params, MPI.COMM_SELF, model_class)
        error = ""
    except SolveError as failure:
        rows, summary, error = failure.run.rows, failure.run.summary, str(failure)
    loading = [r for r in rows if r["stage"] == "load"]
    eps_m = summary.get("eps_m")
    if eps_m is None and loading and loading[-1]["V_over_V0"] <= crater.CLOSURE_CRITERIA.volume:
        eps_m = loading[-1]["eps"]  # closed on loading; a later stage failed
    eps_c = critical_preload(replace(params, preload=0.1))[0] if with_eps_c else None
    return {"variant": name, "change": change, "status": "failed" if error else "ok",
            "eps_m": _number(eps_m), "F_tilde": _number(summary.get("F_tilde")), "eps_c": eps_c,
            "last_eps": loading[-1]["eps"] if loading else None,
            "wall_time_s": time.perf_counter() - t0, "command": command(name), "error": error[:200]}


def _number(value) -> float | None:
    """A number of a row, also as kept in the CSV before its values were plain floats."""
    if value in (None, ""):
        return None
    return float(str(value).removeprefix("np.float64(").removesuffix(")"))


def _against(value, name: str) -> str:
    return "—" if value is None else f"{value:.4f} ({100 * (value / DISSERTATION[name] - 1):+.1f} %)"


def markdown(rows: list[dict]) -> str:
    """The report: benchmarks/templates/crater-closure.md filled from the rows (the CSV)."""
    def shown(r):
        eps_m = _number(r["eps_m"])
        return _against(eps_m, "eps_m") if eps_m is not None else f"— (last {float(r['last_eps']):.4f})"

    columns = [("variant", "{change}"), ("eps_m (against 0.47)", shown),
               ("eps_c (against 0.43)", lambda r: _against(_number(r.get("eps_c")), "eps_c")),
               ("F~", lambda r: "—" if _number(r["F_tilde"]) is None else f"{_number(r['F_tilde']):.3f}"),
               ("status", "{status}"), ("wall time [s]", lambda r: f"{float(r['wall_time_s']):.0f}"),
               ("command", lambda r: f"`{r.get('command') or command(r['variant'])}`")]
    return render("crater-closure.md", rows, {}, dissertation=DISSERTATION, table=table(rows, columns))


def main(names: list[str]) -> None:
    if names == ["--render-only"]:  # the .md again from the CSV, nothing solved
        write_report(OUT / "crater-closure.md", markdown(read_csv(OUT / "crater-closure.csv")))
        return
    configure(MPI.COMM_SELF, quiet=True)
    unknown = [n for n in names if n not in VARIANTS]
    if unknown:
        raise SystemExit(f"unknown variants {unknown}: choose from {list(VARIANTS)}")
    path = OUT / "crater-closure.csv"
    kept = {r["variant"]: r for r in read_csv(path)} if path.exists() else {}
    for name in names or list(VARIANTS):
        kept[name] = closure(name)
        r = kept[name]
        print(f"{name}: {r['status']}, eps_m {r['eps_m']}, eps_c {r['eps_c']}, "
              f"{r['wall_time_s']:.0f} s", flush=True)
        rows = [kept[n] for n in VARIANTS if n in kept]  # written as each variant ends
        atomic_text(path, csv_text(rows, COLUMNS))
        write_report(OUT / "crater-closure.md", markdown(rows))


if __name__ == "__main__":
    main(sys.argv[1:])
