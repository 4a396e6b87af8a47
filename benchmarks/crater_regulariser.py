"""The creasing regulariser over the air crater's whole preload range:
docs/benchmarks/crater-regulariser.{csv,md,png}.

The bar: halving any regularisation changes F~ by less than 1 %. The hemisphere's
one regulariser is the crater wall's surface energy gamma/(mu a) (`--surface-energy`,
default 0.01). Each series below is one `bcfem sweep crater --preload 0:0.5:0.025 ...`
over Fig. 7.6's preloads, kept in `docs/benchmarks/crater-regulariser/<series>/`
(resumable: a rerun solves only missing points, then draws):

* gamma 0.02, 0.01, 0.005, 0.0025: three halvings, and gamma = 0, their limit;
* gamma 0.01 with half the load step (`--strain-step 0.00625`): the same energy, another
  load path. Where its F~ differs from the default's, the cycle has ended in another
  equilibrium of the same model, so F~ is not a function of the parameters there and no
  regulariser can be halved "within 1 %" in a meaningful sense.

Per preload: F~ of every series, the unstable axisymmetric modes of the end state, the
relative change of F~ for each halving and for the halved step, and for each of them the
preloads where it stays below 1 %.

Run from the repository root: `.venv/bin/python benchmarks/crater_regulariser.py`
(part of `make bench`; about 20 min on 2 cores from nothing, seconds when the points are kept);
`--render-only` renders the .md again from its CSV and JSON (the report is
`benchmarks/templates/crater-regulariser.md`).
"""

from __future__ import annotations

import csv
import json
import math
import sys
import time

from common import (
    ROOT,
    atomic_text,
    csv_text,
    fmt,
    mpirun_bcfem,
    provenance,
    provenance_note,
    render,
    render_again,
    save_figure,
    table,
    write_report,
    write_summary,
)

OUT = ROOT / "docs" / "benchmarks"
SWEEPS = OUT / "crater-regulariser"
PRELOADS = "0:0.5:0.025"  # Fig. 7.6
BAR = 0.01  # halving a regulariser changes F~ by less than 1 %
DEFAULT = "gamma=0.01"
SERIES = {  # name: the sweep's arguments
    "gamma=0.02": ["--surface-energy", "0.02"],
    "gamma=0.01": ["--surface-energy", "0.01"],
    "gamma=0.005": ["--surface-energy", "0.005"],
    "gamma=0.0025": ["--surface-energy", "0.0025"],
    "gamma=0": ["--surface-energy", "0"],  # no regulariser: the limit the halvings approach
    "gamma=0.01,half-step": ["--surface-energy", "0.01", "--strain-step", "0.00625"],
}
HALVINGS = [("gamma=0.02", "gamma=0.01"), ("gamma=0.01", "gamma=0.005"), ("gamma=0.005", "gamma=0.0025")]
PATH = (DEFAULT, "gamma=0.01,half-step")
LIMIT_KEY = "gamma=0.0025 against gamma=0"


def sweep(name: str, ranks: int) -> None:
    """Solve the series' missing points (all of them in a new checkout)."""
    mpirun_bcfem(["sweep", "crater", "--preload", PRELOADS, *SERIES[name], "--out", str(SWEEPS / name), "--quiet"],
                 ranks)


def points(name: str) -> dict[float, dict]:
    with (SWEEPS / name / "sweep.csv").open() as f:
        return {round(float(r["preload"]), 6): r for r in csv.DictReader(f)}


def change(a: dict | None, b: dict | None) -> float:
    """|F~(b)/F~(a) - 1| (absolute where F~(a) = 0); nan unless both converged."""
    if not a or not b or a["status"] != "ok" or b["status"] != "ok":
        return math.nan
    fa, fb = float(a["F_tilde"]), float(b["F_tilde"])
    return abs(fb / fa - 1) if fa else abs(fb)


def per_preload() -> list[dict]:
    """One row per preload: F~, unstable modes and stability of every series, and the changes."""
    data = {name: points(name) for name in SERIES}
    rows = []
    for eps in sorted(data[DEFAULT]):
        row = {"eps": eps}
        for name, pts in data.items():
            p = pts.get(eps)
            row[f"F_tilde[{name}]"] = float(p["F_tilde"]) if p and p["status"] == "ok" else math.nan
            row[f"unstable[{name}]"] = p.get("final_unstable_modes", "") if p else ""
            row[f"stability[{name}]"] = (p["stability"] if p["status"] == "ok" else "failed") if p else "missing"
        for coarse, fine in HALVINGS:
            row[f"halving {coarse} -> {fine}"] = change(data[coarse].get(eps), data[fine].get(eps))
        row["step halved"] = change(data[PATH[0]].get(eps), data[PATH[1]].get(eps))
        row[LIMIT_KEY] = change(data["gamma=0"].get(eps), data[HALVINGS[-1][1]].get(eps))
        rows.append(row)
    return rows


def holds_up_to(rows: list[dict], key: str) -> float | None:
    """The largest preload up to which the change ``key`` stays below the bar at every point."""
    last = None
    for r in rows:
        if not r[key] < BAR:  # nan (a failed point) fails too
            break
        last = r["eps"]
    return last


def passing(rows: list[dict], key: str) -> str:
    """The preloads where the change ``key`` is below the bar, as ranges ("0-0.2, 0.3")."""
    runs, current = [], []
    for r in rows:
        if r[key] < BAR:
            current.append(r["eps"])
        elif current:
            runs.append(current)
            current = []
    if current:
        runs.append(current)
    return ", ".join(f"{c[0]:g}" if len(c) == 1 else f"{c[0]:g}-{c[-1]:g}" for c in runs) or "none"


def core_seconds() -> float:
    """The kept points' own solve times, summed over every series (each point records its time)."""
    return sum(json.loads(p.read_text()).get("solve_time_s", 0.0) for p in SWEEPS.glob("*/points/*.json"))


def main() -> None:
    import argparse

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--ranks", type=int, default=2, help="MPI ranks of each sweep (points are spread over them)")
    ap.add_argument("--render-only", action="store_true",
                    help="render crater-regulariser.md again from the crater-regulariser.csv and .json that are there")
    args = ap.parse_args()
    if args.render_only:
        render_again("crater-regulariser", report)
        return
    if args.ranks < 1:
        ap.error(f"--ranks must be a positive integer (got {args.ranks})")
    t0 = time.perf_counter()
    for name in SERIES:
        sweep(name, args.ranks)
    rows = per_preload()
    halving_keys = [f"halving {c} -> {f}" for c, f in HALVINGS]
    atomic_text(OUT / "crater-regulariser.csv", csv_text(rows, list(rows[0])))
    plot(rows, halving_keys)
    summary = {"wall_s": time.perf_counter() - t0, "core_seconds": core_seconds(), "provenance": provenance()}
    write_summary("crater-regulariser", summary)
    write_report(OUT / "crater-regulariser.md", report(rows, summary))
    print(f"wrote {OUT / 'crater-regulariser.md'}", file=sys.stderr)


def plot(rows, halving_keys) -> None:
    from bcfem.plots import pyplot

    plt = pyplot()
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(7.0, 7.0), sharex=True)
    eps = [r["eps"] for r in rows]
    for i, name in enumerate(SERIES):
        top.plot(eps, [r[f"F_tilde[{name}]"] for r in rows], "o-" if "step" not in name else "x--",
                 color=f"C{i}", ms=4, label=name.replace("gamma", "gamma/(mu a)"))
    top.set_ylabel("F~ = F / (p_a A0)")
    top.legend(fontsize=7)
    top.grid(alpha=0.3)
    top.set_title("hemisphere, beta = 0.467, default mesh: F~ against the preload", fontsize=9)
    floor = 1e-8  # identical values drawn at the floor
    for i, key in enumerate(halving_keys + ["step halved"]):
        bottom.semilogy(eps, [max(r[key], floor) if not math.isnan(r[key]) else math.nan for r in rows],
                        "o-" if key != "step halved" else "x--", ms=4, color=f"C{i + 5}",
                        label=key.replace("gamma", "gamma/(mu a)"))
    bottom.axhline(BAR, color="k", lw=0.8, ls="--", label="1 %")
    bottom.set_xlabel("preload eps")
    bottom.set_ylabel(f"|change of F~| (floor {floor:g})")
    bottom.legend(fontsize=7)
    bottom.grid(alpha=0.3, which="both")
    fig.tight_layout()
    save_figure(fig, OUT / "crater-regulariser.png")
    plt.close(fig)


def report(rows: list[dict], summary: dict) -> str:
    """The Markdown report: benchmarks/templates/crater-regulariser.md filled from the rows (CSV, one
    per preload) and the summary (JSON: the run's wall time and the kept points' core-seconds)."""
    names = list(SERIES)
    halving_keys = [f"halving {c} -> {f}" for c, f in HALVINGS]
    halvings = "\n".join(f"* Halving gamma {k.replace('halving ', '').replace('gamma=', '')}: below 1 % for eps <= "
                         f"{fmt(holds_up_to(rows, k), 'g') or 'none'}; at the preloads {passing(rows, k)}."
                         for k in halving_keys)

    def series(n):
        return lambda r: (f"{r[f'F_tilde[{n}]']:.4f} ({r[f'unstable[{n}]']})" if not math.isnan(r[f"F_tilde[{n}]"])
                          else r[f"stability[{n}]"])

    series_table = table(rows, [("eps", "{eps:g}"), *[(n, series(n)) for n in names],
                                ("stability (default)", lambda r: r[f"stability[{DEFAULT}]"])])

    def changed(k):
        def cell(r):
            c = fmt(r[k], ".1e") or "-"
            return f"**{c}**" if c != "-" and float(c) >= BAR else c
        return cell

    change_table = table(rows, [("eps", "{eps:g}"), *[(k.replace("halving ", ""), changed(k)) for k in halving_keys],
                                ("step halved (gamma 0.01)", changed("step halved")), (LIMIT_KEY, changed(LIMIT_KEY))])
    return render("crater-regulariser.md", rows, summary, wall_min=summary["wall_s"] / 60,
                  core_hours=summary["core_seconds"] / 3600, halvings=halvings,
                  path_eps=fmt(holds_up_to(rows, "step halved"), "g") or "none",
                  path_passing=passing(rows, "step halved"), series_table=series_table, change_table=change_table,
                  provenance=provenance_note(summary))


if __name__ == "__main__":
    main()
