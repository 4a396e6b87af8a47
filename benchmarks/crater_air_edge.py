"""The crater's contact radius A2 and the mesh convergence of F~ at eps = 0.2 (scene ``crater``).

Measures, in one process (warm JIT cache, times of ``crater.solve``, not pinned):

* F~ at eps = 0.2 over the meshes size_crater = 0.16 ... 0.035, on the scene's meshes
  (far-field element size max(0.5, size_crater) a, as ``bcfem run crater`` builds them) and
  on meshes refined everywhere (far-field size 4 size_crater a), with F~ both from the
  contact edge located inside its element (:mod:`bcfem.contact.plate_edge`, the scene's rule) and
  from the former rule (midway between the highest wall node on the plate and the next one
  off it), the number of wall nodes on the plate at the end, the observed order and a
  Richardson reference;
* r_edge at the end of loading to eps = 0.3 (the wall rolled onto the plate) on the
  refined meshes, by both rules.

Usage (from the repository root)::

    .venv/bin/python benchmarks/crater_air_edge.py   # ~4 min
    .venv/bin/python benchmarks/crater_air_edge.py --render-only   # the section from CSV + JSON

Writes ``docs/benchmarks/crater-air-edge.{csv,json}`` and, from the template
``benchmarks/templates/crater-air-edge.md``, the section between the markers
``<!-- edge:begin -->`` and ``<!-- edge:end -->`` of ``docs/benchmarks/crater-air.md``.
"""

from __future__ import annotations

import dataclasses
import json
import math
import subprocess
import sys
import time

from mpi4py import MPI

import numpy as np
from common import (
    MONOTONE_MESHES,
    ROOT,
    atomic_text,
    commit,
    csv_text,
    fmt,
    observed_order,
    provenance,
    provenance_note,
    put_section,
    read_csv,
    reference,
    render,
    table,
    write_summary,
)

import bcfem  # noqa: F401
from bcfem.geometry.crater import create_mesh
from bcfem.scenes import crater
from bcfem.scenes.crater.model import Crater
from bcfem.scenes.crater.params import Params

OUT = ROOT / "docs" / "benchmarks"
SIZES = [0.16, 0.12, 0.09, 0.06, 0.045, 0.035]
FAR_RATIO = 4.0  # far-field size over size_crater on the meshes refined everywhere
TEMPLATE = "crater-air-edge.md"
COLUMNS = ["study", "mesh", "eps", "size_crater", "size_far", "dofs", "t_solve_s", "F_tilde", "F_tilde_midpoint",
           "A2_over_A0", "A2_over_A0_midpoint", "p2_over_pa", "V1_over_V0", "V2_over_V0", "wall_nodes_on_plate",
           "r_edge_over_a", "r_edge_midpoint_over_a"]


def midpoint_edge(X, x, tolerance) -> float:
    """The former rule (serial): midway between the highest node on the plate and the next
    one off it; the lowest node's radius if only it is on the plate."""
    order = np.argsort(X[:, 1], kind="stable")
    X, x = X[order], x[order]
    on = np.flatnonzero(x[:, 1] <= tolerance)
    if not len(on):
        return 0.0
    k = on.max()
    if k == 0 or k == len(x) - 1:
        return float(x[k, 0])
    return 0.5 * float(x[k, 0] + x[k + 1, 0])


class Stop(Exception):
    """Ends a run after its loading stage."""


def recording(size_far_ratio: float | None, stop_after_loading: bool = False):
    """A Crater that records, at each observation, the edge by both rules; its far field
    is refined with size_crater when ``size_far_ratio`` is given."""
    records = []

    class Recording(Crater):
        @staticmethod
        def create_mesh(geometry, comm):
            if size_far_ratio is not None:
                geometry = dataclasses.replace(geometry, size_far=size_far_ratio * geometry.size_crater)
            return create_mesh(geometry, comm)

        def observe(self, stage, eps, V1=None):
            if stop_after_loading and stage == "unload":
                raise Stop
            X, zdofs, rdofs = self._wall
            x = np.column_stack([X[:, 0] + self.u.x.array[rdofs], X[:, 1] + self.u.x.array[zdofs]])
            tolerance = 1e-6 * self.geometry.crater_radius
            records.append({"stage": stage, "eps": eps, "r_edge": self.open_radius(),
                            "r_mid": midpoint_edge(X[:, :2], x, tolerance),
                            "on_plate": int(np.sum(x[:, 1] <= tolerance)), "a": self.geometry.crater_radius})
            return super().observe(stage, eps, V1)

    return Recording, records


def cycle(size: float, ratio: float | None) -> dict:
    model_class, records = recording(ratio)
    t = time.perf_counter()
    _, s = crater.solve(Params(preload=0.2, size_crater=size), MPI.COMM_SELF, model_class)
    elapsed = time.perf_counter() - t
    last = records[-1]
    scale = (last["r_mid"] / last["r_edge"]) ** 2  # F~ and A2 scale with r_edge^2
    return {"study": "eps0.2", "mesh": "scene" if ratio is None else "refined", "eps": 0.2, "size_crater": size,
            "size_far": max(0.5, size) if ratio is None else ratio * size, "dofs": s["dofs"], "t_solve_s": elapsed,
            "F_tilde": s["F_tilde"], "F_tilde_midpoint": s["F_tilde"] * scale, "A2_over_A0": s["A2_over_A0"],
            "A2_over_A0_midpoint": s["A2_over_A0"] * scale, "p2_over_pa": s["p2_over_pa"],
            "V1_over_V0": s["V1_over_V0"], "V2_over_V0": s["V2_over_V0"], "wall_nodes_on_plate": last["on_plate"],
            "r_edge_over_a": last["r_edge"] / last["a"], "r_edge_midpoint_over_a": last["r_mid"] / last["a"]}


def loaded(size: float, eps: float = 0.3) -> dict:
    model_class, records = recording(FAR_RATIO, stop_after_loading=True)
    t = time.perf_counter()
    try:
        crater.solve(Params(preload=eps, size_crater=size), MPI.COMM_SELF, model_class)
    except Exception as error:  # the runner may wrap it
        if "Stop" not in repr(error) and not isinstance(error, Stop):
            raise
    last = records[-1]
    assert last["stage"] == "load" and math.isclose(last["eps"], eps)
    return {"study": "load0.3", "mesh": "refined", "eps": eps, "size_crater": size, "size_far": FAR_RATIO * size,
            "t_solve_s": time.perf_counter() - t, "wall_nodes_on_plate": last["on_plate"],
            "r_edge_over_a": last["r_edge"] / last["a"], "r_edge_midpoint_over_a": last["r_mid"] / last["a"]}


def convergence(series, key):
    """Differences, observed order (3 finest) and the reference of :func:`common.reference`."""
    ref = reference([{"size_crater": r["size_crater"], "F_tilde": r[key]} for r in series])
    h = [r["size_crater"] for r in series]
    orders = [observed_order(h[i:i + 3], [r[key] for r in series[i:i + 3]]) for i in range(len(series) - 2)]
    return ref, orders


def section(rows: list[dict], summary: dict) -> str:
    """This benchmark's section of docs/benchmarks/crater-air.md: the template
    benchmarks/templates/crater-air-edge.md filled from the rows (CSV) and the summary (JSON)."""
    meshes = []
    for mesh in ("scene", "refined"):
        series = [r for r in rows if r["study"] == "eps0.2" and r["mesh"] == mesh]
        ref, orders = convergence(series, "F_tilde")
        same = all(r["F_tilde"] == r["F_tilde_midpoint"] for r in series)
        reference_ = (f"Richardson reference (order {ref['order']:.2f}, meshes {ref['meshes_used'][0]:g} and "
                      f"{ref['meshes_used'][1]:g}): F~ = {ref['F']:.9f}." if ref["kind"] == "richardson" else
                      f"No Richardson reference: the finest {MONOTONE_MESHES} meshes do not converge monotonically "
                      f"(criterion of `crater_air.py`); the finest mesh gives F~ = {ref['F']:.9f}.")
        meshes.append(render(TEMPLATE, rows, summary, section="mesh", mesh=mesh, table=table(series, [
            ("size_crater", "{size_crater:g}"), ("size_far / a", "{size_far:g}"), ("dofs", "{dofs}"),
            ("F~", "{F_tilde:.9f}"), ("F~ (midpoint)", "{F_tilde_midpoint:.9f}"), ("A2/A0", "{A2_over_A0:.9f}"),
            ("p2/pa", "{p2_over_pa:.9f}"), ("on plate", "{wall_nodes_on_plate}"), ("t [s]", "{t_solve_s:.1f}")]),
            differences=", ".join(f"{x:+.2e}" for x in ref["differences"]), sign_changes=ref["sign_changes"],
            orders=", ".join(fmt(p, ".2f") or "-" for p in orders),
            reference=reference_ + (" Both rules give the same F~ on every mesh: only the rim node is on the plate."
                                    if same else "")))
    loads = [r for r in rows if r["study"] == "load0.3"]
    loaded_ = ""
    if loads:
        spread = [max(r[k] for r in loads) - min(r[k] for r in loads)
                  for k in ("r_edge_over_a", "r_edge_midpoint_over_a")]
        loaded_ = render(TEMPLATE, rows, summary, section="loaded", located=spread[0], midpoint=spread[1],
                         table=table(loads, [
                             ("size_crater", "{size_crater:g}"), ("on plate", "{wall_nodes_on_plate}"),
                             ("r_edge / a", "{r_edge_over_a:.5f}"), ("r_edge / a (midpoint)", "{r_edge_midpoint_over_a:.5f}"),
                             ("t [s]", "{t_solve_s:.1f}")]))
    return render(TEMPLATE, rows, summary, far_ratio=FAR_RATIO, meshes="".join(meshes), loaded=loaded_,
                  provenance=provenance_note(summary)).rstrip("\n")


def main():
    rows = []
    for ratio in (None, FAR_RATIO):
        for size in SIZES:
            rows.append(cycle(size, ratio))
            print({k: rows[-1][k] for k in ("mesh", "size_crater", "dofs", "F_tilde", "F_tilde_midpoint",
                                            "wall_nodes_on_plate", "t_solve_s")}, flush=True)
    for size in SIZES:
        rows.append(loaded(size))
        print({k: rows[-1][k] for k in ("size_crater", "wall_nodes_on_plate", "r_edge_over_a",
                                        "r_edge_midpoint_over_a")}, flush=True)
    dirty = subprocess.run(["git", "status", "--porcelain", "bcfem"], capture_output=True, text=True,
                           cwd=ROOT).stdout.strip()
    summary = {"bcfem": f"bcfem @ {commit()}{' with uncommitted changes in bcfem/' if dirty else ''}",
               "provenance": provenance()}
    atomic_text(OUT / "crater-air-edge.csv", csv_text(rows, COLUMNS))
    write_summary("crater-air-edge", summary)
    put_section(OUT / "crater-air.md", "edge", section(rows, summary))


if __name__ == "__main__":
    if sys.argv[1:] == ["--render-only"]:  # the section again from the CSV and JSON, nothing solved
        put_section(OUT / "crater-air.md", "edge", section(read_csv(OUT / "crater-air-edge.csv"),
                                                           json.loads((OUT / "crater-air-edge.json").read_text())))
    else:
        main()
