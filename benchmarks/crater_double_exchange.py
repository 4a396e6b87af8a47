"""Fig. 9.9: the dissertation's double-chamber model (``--chambers membrane``) against C_V.

The dissertation's crater (r0 = 0.52 H, R0 = 0.5 H, s = 0.03 H, mu = p_a, sticking plate,
air sealed at rest) in an isolated specimen, loaded to eps_z = eps_a = 0.13 (the figure's
caption; its text says 0.2, which the disconnected model does not reach on this mesh: Newton
stalls at 0.173), as three models on one mesh (§9.3):

1. one cavity (C_V = 0, no membrane stiffness): the chambers connected;
2. the membrane from eps = 0, no exchange (C_V = inf): disconnected;
3. the membrane with exchange (eq. 9.1) at a constant C_V over the whole loading.

(p_c1 - p_c2)/p_a and (V_c1 - V_c2)/V at eps = 0.13, V the cavity's volume at rest, the
chambers divided at the membrane in all three. The node pair is the probe's (``auto``:
the pair of closest approach on the probe's loading to 0.13). Also: the membrane's stiffness (Model 2
at mu_m t/(mu H) = 0, 1e-6 (the default) and 1e-2).
Serial, in process (loading only: Fig. 9.9 needs no unloading), a few minutes.

Usage (from the repository root)::

    .venv/bin/python benchmarks/crater_double_exchange.py
    .venv/bin/python benchmarks/crater_double_exchange.py --render-only   # the .md again from CSV + JSON

Writes ``docs/benchmarks/crater-double-exchange.{csv,json,md,png}``; the report is
``benchmarks/templates/crater-double-exchange.md`` filled from the CSV and the JSON.
"""

from __future__ import annotations

import math
import sys
import time
from dataclasses import replace

from mpi4py import MPI

from common import (
    ROOT,
    atomic_text,
    csv_text,
    provenance,
    provenance_note,
    render,
    render_again,
    save_figure,
    table,
    write_report,
    write_summary,
)

from bcfem.run.runner import solve
from bcfem.scenes.crater_double import Params
from bcfem.scenes.crater_double.membrane import MembraneCycle, node_pair

OUT = ROOT / "docs" / "benchmarks"
#: the mesh of chapter 9's coarse studies, the dissertation's eps_z
BASE = dict(size_wall=0.08, size_contact=0.02, preload=0.13, chambers="membrane")
CVS = (1e-3, 0.1, 1.0, 10.0, 1e3, 1e5)
COLUMNS = ["model", "C_V", "membrane_stiffness", "strain_step", "dp_over_pa", "dV_over_V", "p_c1_over_pa",
           "p_c2_over_pa", "mass_conservation", "t_solve_s"]
COMMAND = ".venv/bin/python benchmarks/crater_double_exchange.py"


class Loading(MembraneCycle):
    """The membrane model's loading alone."""

    unloads = False


def at_preload(params: Params, model: str) -> dict:
    t0 = time.perf_counter()
    run, summary = solve(Loading(params, MPI.COMM_SELF), MPI.COMM_SELF)
    last = run.rows[-1]
    V = last["V_c1"] + last["V_c2"]  # over V0
    return {"model": model, "C_V": params.exchange_before, "membrane_stiffness": params.membrane_stiffness,
            "strain_step": params.strain_step, "dp_over_pa": last["p_c1_over_pa"] - last["p_c2_over_pa"],
            "dV_over_V": last["V_c1"] - last["V_c2"], "V_over_V0": V, "p_c1_over_pa": last["p_c1_over_pa"],
            "p_c2_over_pa": last["p_c2_over_pa"],
            "mass_conservation": max(r["fluid_law_residual"] for r in run.rows if r["fluid_law_residual"] is not None),
            "t_solve_s": time.perf_counter() - t0}


def figure(rows, one, two):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    three = [r for r in rows if r["model"] == "3" and r["strain_step"] == BASE_STEP]
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.4))
    for ax, key, label in ((axes[0], "dp_over_pa", "(p_c1 - p_c2)/p_a"), (axes[1], "dV_over_V", "(V_c1 - V_c2)/V")):
        ax.semilogx([r["C_V"] for r in three], [r[key] for r in three], "ko-", ms=4, label="Model 3 (exchange)")
        ax.axhline(one[key], color="tab:green", ls="--", label="Model 1 (one cavity)")
        ax.axhline(two[key], color="tab:red", ls="--", label="Model 2 (no exchange)")
        ax.set_xlabel("C_V (normalised, see --help)")
        ax.set_ylabel(label)
        ax.set_title(f"{label} at ε_z = {BASE['preload']}", fontsize=9)
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    return fig


BASE_STEP = Params.strain_step


def main() -> None:
    pair = node_pair(Params(**BASE), MPI.COMM_SELF)
    print("node pair:", {k: v for k, v in pair.items() if k != "probe"}, flush=True)
    given = Params(**BASE, membrane_sidewall=pair["Z_sidewall"], membrane_protuberance=pair["Z_protuberance"],
                   switch_strain=BASE["preload"])  # C_V constant over the loading
    rows = [at_preload(replace(given, exchange_before=0.0, membrane_stiffness=0.0), "1")]
    for k in (0.0, 1e-2):
        rows.append(at_preload(replace(given, exchange_before=math.inf, membrane_stiffness=k), "2"))
        print(rows[-1], flush=True)
    rows.append(at_preload(replace(given, exchange_before=math.inf), "2"))
    two = rows[-1]
    for cv in CVS:
        rows.append(at_preload(replace(given, exchange_before=cv), "3"))
        print(rows[-1], flush=True)
    one = rows[0]
    atomic_text(OUT / "crater-double-exchange.csv", csv_text(rows, COLUMNS))
    save_figure(figure(rows, one, two), OUT / "crater-double-exchange.png")
    summary = {"pair": {k: v for k, v in pair.items() if k != "probe"}, "provenance": provenance()}
    write_summary("crater-double-exchange", summary)
    write_report(OUT / "crater-double-exchange.md", report(rows, summary))


def report(rows: list[dict], summary: dict) -> str:
    """The Markdown report: benchmarks/templates/crater-double-exchange.md filled from the rows
    (CSV: Model 1 first, then Model 2, the last of which is the reference) and the node pair (JSON)."""
    one = rows[0]
    two = [r for r in rows if r["model"] in (2, "2")][-1]
    span_p, span_v = two["dp_over_pa"] - one["dp_over_pa"], two["dV_over_V"] - one["dV_over_V"]

    def to(key: str, model: dict, span: float):
        return lambda r: f"{(r[key] - model[key]) / span:+.2e}"

    text = table(rows, [
        ("model", "{model}"), ("C_V", "{C_V:g}"), ("μ_m t/(μ H)", "{membrane_stiffness:g}"),
        ("strain step", "{strain_step:g}"), ("(p_c1 − p_c2)/p_a", "{dp_over_pa:.6f}"),
        ("(V_c1 − V_c2)/V0", "{dV_over_V:.6f}"), ("to 1 (p)", to("dp_over_pa", one, span_p)),
        ("to 2 (p)", to("dp_over_pa", two, span_p)), ("to 1 (V)", to("dV_over_V", one, span_v)),
        ("to 2 (V)", to("dV_over_V", two, span_v)), ("mass conservation", "{mass_conservation:.1e}"),
        ("s", "{t_solve_s:.0f}")])
    return render("crater-double-exchange.md", rows, summary, table=text, size_wall=BASE["size_wall"],
                  size_contact=BASE["size_contact"], preload=BASE["preload"], strain_step=BASE_STEP,
                  provenance=provenance_note(summary))


if __name__ == "__main__":
    if sys.argv[1:] == ["--render-only"]:
        render_again("crater-double-exchange", report)
    else:
        main()
