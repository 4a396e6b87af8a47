# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
#       format_version: '1.3'
# ---

# %% [markdown]
# # The crater design space (dissertation Figures 7.9-7.12, 8.4, 8.6b, 8.7b-f)
#
# Scene `crater` (`bcfem/scenes/crater.py`) over its design parameters: the
# crater aspect $\alpha = b/a$, the stiffness $\beta = \mu/p_a$, a reinforcement
# layer ($\alpha' = t/a$, $\beta' = \mu_l/\mu$), the preload $\varepsilon$ and
# the fluid (air: Boyle's law; liquid: incompressible, $V_2 = V_1$).
#
# * **Air, full closure** (section 7.3): every point is loaded to $\varepsilon_m$,
#   the smallest preload with $V_1 = 0$ (`--preload closure`, found by
#   bisection), so $\tilde F = A_2/A_0$ (eq. 7.17). Fig. 7.9: $\tilde F(\alpha,
#   \beta)$ with the 'good' line $\tilde F = 0.8$ and $\varepsilon_m(\alpha)$;
#   Fig. 7.10: the shapes after unloading.
# * **Reinforced, air** (section 7.4): Fig. 7.11b, the $\alpha'$-$\beta'$ map at
#   $\alpha = \beta = 1$ classified from the tangent's inertia (stable /
#   unstable on unloading only / on loading and unloading) with the
#   $\tilde F > 1$ region; Fig. 7.11c, $\tilde F(\alpha)$ at $\alpha' = 0.03$,
#   $\beta' = 30$; Fig. 7.12, the four deformation types as frame sequences.
# * **Liquid** (chapter 8), $\hat F = -\Delta p A_2/(\mu A_0)$ (eq. 8.7):
#   Fig. 8.4, air against liquid for the hemisphere; Fig. 8.6b,
#   $\hat F(\alpha, \varepsilon)$; Fig. 8.7b, unreinforced against reinforced at
#   $\varepsilon = 0.25$; 8.7c, d, contours with two layers; 8.7e, f,
#   $\hat F(\beta')$. A liquid crater that closes on loading gives $\hat F = 0$
#   (eq. 8.8); the scene says so in its summary.
#
# Each map is one `bcfem sweep crater` command (listed in `summary.json` and in
# `docs/craters.md`); its points are kept under `--out/sweeps/<map>`, so the
# command line and this demo share them, and a rerun solves only what is
# missing. The recorded shape cycles are kept under `--out/sweeps/shapes` the same
# way. The default grid is a few points of each kind (CI, serial and
# `mpirun -n 2`); `--full` solves the published maps (about 200 cycles).
#
# Fig. 7.11b's classes are the dissertation's wrinkles, i.e. symmetry breaking: its map
# checks the non-axisymmetric modes n = 1..20 after every step (`waves = 20`,
# `bcfem/modes.py`) and is coloured by `stability_waves`; `stability` (axisymmetric
# modes and snaps) is in the CSV too.

# %%
import argparse
import json
import os
import pickle
import textwrap
import time
from dataclasses import asdict, replace

from mpi4py import MPI

import numpy as np

import bcfem  # noqa: F401  (before dolfinx / petsc4py)
from bcfem import demo, io, sweep
from bcfem.scenes import crater
from bcfem.scenes.crater import frames as crater_frames

# %% [markdown]
# ## The maps
#
# `MAPS[name] = (base parameters, {grid axis: values})`; the quick grid takes a
# subset of the same values, so its points are the full maps' points.

# %%
AIR = crater.Params(preload=crater.PRELOAD_TO_CLOSURE)  # the experiment's specimen, default mesh and surface energy
LIQUID = crater.Params(fluid="liquid")
ALPHAS = [0.25, 0.4, 0.55, 0.7, 0.85, 1.0]
STIFFNESS = [3.0, 10.0, 30.0, 100.0, 300.0]
MAPS = {
    "fig7_9": (AIR, {"alpha": ALPHAS, "beta": [0.5, 1.0, 2.0, 5.0, 10.0]}),
    "fig7_11b": (replace(AIR, alpha=1.0, beta=1.0, waves=20),
                 {"layer_thickness": [0.015, 0.03, 0.045, 0.06], "layer_stiffness": STIFFNESS}),
    "fig7_11c": (replace(AIR, beta=1.0, layer_thickness=0.03, layer_stiffness=30.0),
                 {"alpha": [0.4, 0.55, 0.7, 0.85, 1.0]}),
    "fig8_4": (LIQUID, {"preload": [0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.4, 0.45, 0.5]}),
    "fig8_4_air": (crater.Params(), {"preload": [0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.4, 0.45, 0.5]}),
    "fig8_6b": (LIQUID, {"alpha": [0.25, 0.5, 0.75, 1.0], "preload": [0.1, 0.2, 0.3, 0.4, 0.5]}),
    "fig8_7b_plain": (replace(LIQUID, preload=0.25), {"alpha": [0.1, 0.25, 0.4, 0.55, 0.7, 0.85, 1.0]}),
    "fig8_7b_layer": (replace(LIQUID, preload=0.25, layer_thickness=0.03, layer_stiffness=30.0),
                      {"alpha": [0.1, 0.25, 0.4, 0.55, 0.7, 0.85, 1.0]}),
    "fig8_7c": (replace(LIQUID, layer_thickness=0.03, layer_stiffness=30.0),
                {"alpha": [0.5, 0.75, 1.0], "preload": [0.1, 0.2, 0.3, 0.4, 0.5]}),
    "fig8_7d": (replace(LIQUID, layer_thickness=0.05, layer_stiffness=100.0),
                {"alpha": [0.5, 0.75, 1.0], "preload": [0.1, 0.2, 0.3, 0.4, 0.5]}),
    "fig8_7e": (replace(LIQUID, alpha=1.0, preload=0.4),
                {"layer_thickness": [0.03, 0.05, 0.07, 0.09], "layer_stiffness": STIFFNESS}),
    "fig8_7f": (replace(LIQUID, alpha=1.0, layer_thickness=0.05),
                {"preload": [0.3, 0.35, 0.4, 0.45], "layer_stiffness": STIFFNESS}),
}
QUICK = {"fig7_9": {"alpha": [0.4, 0.55], "beta": [1.0, 5.0]}, "fig7_11c": {"alpha": [0.55]},
         "fig8_4": {"preload": [0.2]}, "fig8_4_air": {"preload": [0.2]}, "fig8_7b_layer": {"alpha": [0.55]}}
# Fig. 7.10's shapes (alpha, beta) and Fig. 7.12's four reinforced hemispheres (alpha', beta'), full grid
SHAPES_7_10 = [(a, b) for b in (0.5, 1.0, 10.0) for a in (0.25, 0.5, 0.75, 1.0)]
TYPES_7_12 = {"a": (0.015, 2.0), "b": (0.055, 40.0), "c": (0.015, 80.0), "d": (0.03, 80.0)}
QUICK_SHAPES = {"7_10": [(0.55, 1.0)], "7_12": {}}
# the dissertation's numbers (text of sections 7.3, 7.4, 8.2-8.4)
DISSERTATION = {
    "fig7_9_optimum_beta1": {"alpha": 0.7, "F_tilde": 0.84},
    "fig7_9b_eps_m_hemisphere": 0.47,
    "fig7_11b_F_above_1": {"layer_thickness": [0.015, 0.045], "layer_stiffness": [10, 50], "F_tilde": [0.99, 1.09]},
    "fig7_11c_peak": {"alpha": 0.85, "F_tilde": 1.17},
    "fig7_12_F_tilde": {"a": 0.70, "b": 0.94, "c": 1.07, "d": 0.91},
    "fig8_4_liquid_eps_c": 0.33,
    "fig8_6b_optimum": {"alpha": 1.0, "preload": 0.4},
    "fig8_7b_peaks": {"plain": {"alpha": 0.65, "F_hat": 0.91}, "layer": {"alpha": 0.85, "F_hat": 1.38}},
    "fig8_7cd_optimum": {"fig8_7c": {"alpha": 1.0, "preload": 0.39}, "fig8_7d": {"alpha": 1.0, "preload": 0.47}},
}
CLOSED = crater.CLOSURE_CRITERIA.closed

comm = MPI.COMM_WORLD
args, report = demo.setup("crater_design", "Dissertation Figures 7.9-7.12, 8.4, 8.6b, 8.7: the crater design space",
                          comm)
extra = argparse.ArgumentParser(add_help=False)
extra.add_argument("--full", action="store_true", help="the published maps (about 200 cycles)")
full = extra.parse_known_args()[0].full


def command(name: str) -> str:
    """The ``bcfem sweep crater`` command of a map (the same points as this demo's)."""
    base, axes = MAPS[name]
    default = crater.Params()
    fixed = [f"--{k.replace('_', '-')} {'closure' if k == 'preload' and v == crater.PRELOAD_TO_CLOSURE else f'{v:g}'}"
             if k != "fluid" else f"--fluid {v}"
             for k, v in asdict(base).items() if v != getattr(default, k) and k not in axes]
    grid = [f"--grid {k}={','.join(f'{v:g}' for v in values)}" for k, values in axes.items()]
    return " ".join(["mpirun -n 2 bcfem sweep crater", *fixed, *grid,
                     f"--out docs/figures/crater_design/sweeps/{name}"])


# %% [markdown]
# ## Solve the maps
#
# `bcfem.sweep.run` spreads each map's points over the ranks (each point a
# serial cycle, `crater.sweep_point`) and records a failed point with its
# reason.

# %%
results, timing = {}, {}
for name, (base, axes) in MAPS.items():
    if not full:
        if name not in QUICK:
            continue
        axes = QUICK[name]
    t0 = time.perf_counter()
    points = sweep.grid_points(base, [(k, np.array(v)) for k, v in axes.items()])
    rows = sweep.run(points, crater.sweep_point, args.out / "sweeps" / name, comm)
    results[name] = rows
    # this run's wall time is near zero when the points come from the cache; the points'
    # own solve times (serial, one rank each) are the cost of the map
    timing[name] = {"points": len(rows), "wall_time_s": time.perf_counter() - t0, "ranks": comm.size,
                    "point_solve_time_s": sum(r.get("solve_time_s", 0.0) for r in rows)}
    failed = [r for r in rows if r["status"] != "ok"]
    report(f"{name}: {len(rows)} points, {len(failed)} failed ({timing[name]['wall_time_s']:.0f} s; "
           f"points' own solve times {timing[name]['point_solve_time_s']:.0f} s)")
    for r in failed:
        report(f"  FAILED {sweep.point_key({k: r[k] for k in axes})}: {r['reason']}")


def ok(name):
    return [r for r in results.get(name, []) if r["status"] == "ok"]


def best(rows, key):
    return max(rows, key=lambda r: r[key]) if rows else None


def on_saddle(r) -> bool:
    """The cycle ended on an unstable equilibrium: its force is not one a specimen holds."""
    return r["status"] == "ok" and (r.get("final_unstable_modes") or 0) > 0


def still_open(name, r) -> bool:
    """A closure run whose crater is still open at the closure limit (eps_m None): its force
    is that of the cycle from eps = crater.MAX_CLOSURE_PRELOAD, not of a closed crater."""
    return MAPS[name][0].preload == crater.PRELOAD_TO_CLOSURE and r["status"] == "ok" and r.get("eps_m", 0) is None


def stays_closed(name, r) -> bool:
    """An air crater closed on loading that the vacuum holds shut through the unloading: no
    cavity, so F ~ 0 (a soft or shallow crater; the summary's closure_note says so)."""
    return (MAPS[name][0].fluid == "air" and r["status"] == "ok" and r.get("eps_m") is not None
            and r["V2_over_V0"] <= crater.CLOSURE_CRITERIA.volume)


def optimum(r, *keys) -> dict:
    return {**{k: r[k] for k in keys}, "ends_on_saddle": on_saddle(r)}


# %% [markdown]
# ## Deformed shapes (Figs. 7.10, 7.12)
#
# Solved again with `crater_frames.Recorder`, which keeps the states the cycle
# observes. Each rank takes the next cycle no rank has taken (a claim file), records
# it alone and keeps it in the cache; rank 0 draws them all.

# %%
shapes_7_10, types_7_12, shape_failures, failed_shapes = {}, {}, [], {}
cycles = [("7_10", (alpha, beta), replace(AIR, alpha=alpha, beta=beta))
          for alpha, beta in (SHAPES_7_10 if full else QUICK_SHAPES["7_10"])]
cycles += [("7_12", tag, replace(AIR, alpha=1.0, beta=1.0, layer_thickness=thickness, layer_stiffness=stiffness))
           for tag, (thickness, stiffness) in (TYPES_7_12 if full else QUICK_SHAPES["7_12"]).items()]
shape_cache = args.out / "sweeps" / "shapes"
cached = [shape_cache / f"cycle{sweep.point_key({}, params)}.pkl" for _, _, params in cycles]
if comm.rank == 0:
    shape_cache.mkdir(parents=True, exist_ok=True)
    for stale in shape_cache.glob("*.claim"):  # left by a run that was stopped
        stale.unlink()
comm.barrier()
t0 = time.perf_counter()
failures = {}
for index, (_, key, params) in enumerate(cycles):
    path = cached[index]
    try:
        os.close(os.open(path.with_suffix(".claim"), os.O_CREAT | os.O_EXCL | os.O_WRONLY))
    except FileExistsError:
        continue  # another rank has it
    if not path.exists():
        try:  # a failure is reported and listed, not fatal
            partial = path.with_suffix(".tmp")  # renamed once complete
            partial.write_bytes(pickle.dumps(crater_frames.record(params)))
            partial.replace(path)
        except Exception as error:
            failures[index] = f"{type(error).__name__}: {error}"
failures = {i: f for part in comm.allgather(failures) for i, f in part.items()}
if comm.rank == 0:
    for claim in shape_cache.glob("*.claim"):
        claim.unlink()
for index, (figure, key, _) in enumerate(cycles):
    if index in failures:
        shape_failures.append({"case": str(key), "reason": failures[index]})
        failed_shapes[key] = failures[index]
        report(f"  FAILED shape cycle {key}: {failures[index]}")
    else:
        (shapes_7_10 if figure == "7_10" else types_7_12)[key] = pickle.loads(cached[index].read_bytes())
timing["shapes"] = {"cycles": len(shapes_7_10) + len(types_7_12), "wall_time_s": time.perf_counter() - t0,
                    "ranks": comm.size}

# %% [markdown]
# ## Compare with the dissertation
#
# Optima are read off our grids (no interpolation): the grid value with the
# largest force.

# %%
ours = {}
column = [r for r in ok("fig7_9") if r["beta"] == 1.0]
if column:
    top = best(column, "F_tilde")
    ours["fig7_9_optimum_beta1"] = optimum(top, "alpha", "F_tilde")
hemisphere = [r["preload"] for r in ok("fig7_9") if r["alpha"] == 1.0]
if hemisphere:
    ours["fig7_9b_eps_m_hemisphere"] = hemisphere[0]
above = [r for r in ok("fig7_11b") if r["F_tilde"] > 1.0]
ours["fig7_11b_F_above_1"] = [{k: r[k] for k in ("layer_thickness", "layer_stiffness", "F_tilde")} for r in above]
ours["fig7_11b_classes"] = {cls: [(r["layer_thickness"], r["layer_stiffness"]) for r in ok("fig7_11b")
                                  if r.get("stability_waves") == cls]
                            for cls in ("stable", "unstable-unloading", "unstable-both")}
if ok("fig7_11c"):
    top = best(ok("fig7_11c"), "F_tilde")
    ours["fig7_11c_peak"] = optimum(top, "alpha", "F_tilde")
ours["fig7_12_F_tilde"] = {tag: summary["F_tilde"] for tag, (summary, _) in types_7_12.items()}
ours["fig7_12_stability"] = {tag: summary["stability"] for tag, (summary, _) in types_7_12.items()}
if ok("fig8_6b"):
    top = best(ok("fig8_6b"), "F_hat")
    ours["fig8_6b_optimum"] = optimum(top, "alpha", "preload", "F_hat")
peaks = {kind: best(ok(f"fig8_7b_{kind}"), "F_hat") for kind in ("plain", "layer")}
ours["fig8_7b_peaks"] = {kind: optimum(r, "alpha", "F_hat") for kind, r in peaks.items() if r}
ours["fig8_7cd_optimum"] = {name: optimum(r, "alpha", "preload", "F_hat")
                            for name in ("fig8_7c", "fig8_7d") if (r := best(ok(name), "F_hat"))}
ours["points_open_at_the_closure_limit"] = {
    name: [{k: r[k] for k in MAPS[name][1]} for r in rows if still_open(name, r)] for name, rows in results.items()}
ours["points_closed_after_unloading"] = {
    name: [{k: r[k] for k in MAPS[name][1]} for r in rows if stays_closed(name, r)] for name, rows in results.items()}
ours["points_traced_twice"] = {name: [{k: r[k] for k in MAPS[name][1]} for r in rows if r.get("retraced")]
                               for name, rows in results.items()}
ours["points_ending_on_a_saddle"] = {name: [{k: r[k] for k in MAPS[name][1]} for r in rows if on_saddle(r)]
                                     for name, rows in results.items()}
for key, value in ours.items():
    report(f"{key}: ours {json.dumps(value)}; dissertation {json.dumps(DISSERTATION.get(key))}")

# %% [markdown]
# ## Write results
#
# `crater_design.csv`: every point of every map (failed ones with their
# reason); `summary.json`: the commands, timings, our optima against the
# dissertation's, and the shape cycles' summaries.

# %%
COLUMNS = ["map", "fluid", "alpha", "beta", "layer_thickness", "layer_stiffness", "preload", "status", "F_tilde",
           "F_hat", "V1_over_V0", "V2_over_V0", "p2_over_pa", "A2_over_A0", "eps_at_zero_force", "stability",
           "stability_waves", "retraced", "reason"]
table = []
for name, rows in results.items():
    base = asdict(MAPS[name][0])
    for r in rows:
        row = {**{k: base[k] for k in ("fluid", "alpha", "beta", "layer_thickness", "layer_stiffness", "preload")},
               **r, "map": name}
        table.append({k: (float(v) if isinstance(v, (float, np.floating)) else v) for k, v in row.items()
                      if k in COLUMNS})
io.write_csv(args.out / "crater_design.csv", table, comm, columns=COLUMNS)


def shape_summary(summary):
    return {k: summary[k] for k in ("F_tilde", "preload", "A2_over_A0", "stability", "wall_time_s")} | {
        "events": [{k: e[k] for k in ("stage", "eps", "kind", "unstable")} for e in summary["instabilities"]]}


io.write_json(args.out / "summary.json", {
    "grid": "full" if full else "quick",
    "commands": {name: command(name) for name in MAPS},
    "timing": timing,
    "ours": ours, "dissertation": DISSERTATION,
    "failed_shape_cycles": shape_failures,
    "failed": [{"map": name, **{k: r[k] for k in MAPS[name][1] if k in r}, "reason": r["reason"]}
               for name, rows in results.items() for r in rows if r["status"] != "ok"],
    "shapes_7_10": [{"alpha": a, "beta": b, **shape_summary(s)} for (a, b), (s, _) in shapes_7_10.items()],
    "types_7_12": {tag: {"layer_thickness": TYPES_7_12[tag][0], "layer_stiffness": TYPES_7_12[tag][1],
                         **shape_summary(s)} for tag, (s, _) in types_7_12.items()},
    "ranks": comm.size,
}, comm)

# %% [markdown]
# ## Plots (rank 0)
#
# Contours are drawn over the grid points (dots; failed points are crosses and
# left blank; a point whose cycle ends on an unstable equilibrium is ringed in red,
# and so is a curve's point; a closure run still open at eps = 0.85 is boxed in orange). A map with fewer than two values on an axis (the quick grid) is
# drawn as labelled dots.

# %%
STABILITY_COLOURS = {"stable": "tab:blue", "unstable-unloading": "tab:red", "unstable-both": "tab:green"}


def field(rows, x, y, key):
    xs, ys = sorted({r[x] for r in rows}), sorted({r[y] for r in rows})
    Z = np.full((len(ys), len(xs)), np.nan)
    for r in rows:
        if r["status"] == "ok":
            Z[ys.index(r[y]), xs.index(r[x])] = r[key]
    return xs, ys, Z


def contour(ax, name, x, y, key, label, lines=()):
    rows = results.get(name, [])
    if not rows:
        ax.text(0.5, 0.5, "not in the quick grid\n(--full)", ha="center", va="center", transform=ax.transAxes)
        return
    xs, ys, Z = field(rows, x, y, key)
    if len(xs) > 1 and len(ys) > 1:
        cs = ax.contourf(xs, ys, Z, levels=12, cmap="viridis")
        ax.figure.colorbar(cs, ax=ax, label=label)
        for level, style in lines:
            ax.contour(xs, ys, Z, levels=[level], colors="k", linestyles=style, linewidths=1.6)
    for r in rows:
        if on_saddle(r):  # ringed: the force of an unstable end state
            ax.plot(r[x], r[y], "o", mfc="none", mec="r", ms=8)
        if still_open(name, r):  # boxed: not closed by the closure limit
            ax.plot(r[x], r[y], "s", mfc="none", mec="orange", ms=9)
        if r["status"] == "ok":
            ax.plot(r[x], r[y], ".", color="w" if len(xs) > 1 and len(ys) > 1 else "k", ms=4)
            ax.annotate(f"{r[key]:.2f}", (r[x], r[y]), fontsize=6, xytext=(2, 2), textcoords="offset points")
        else:
            ax.plot(r[x], r[y], "x", color="r", ms=7)
    ax.set_xlabel(x)
    ax.set_ylabel(y)


def curve(ax, name, x, key, label, **style):
    rows = sorted(ok(name), key=lambda r: r[x])
    ax.plot([r[x] for r in rows], [r[key] for r in rows], "-o", ms=4, label=label, **style)
    saddles = [r for r in rows if on_saddle(r)]
    ax.plot([r[x] for r in saddles], [r[key] for r in saddles], "o", mfc="none", mec="r", ms=9)
    for r in results.get(name, []):
        if r["status"] != "ok":
            ax.axvline(r[x], color="r", lw=0.6, ls=":")


if comm.rank == 0:
    from bcfem.plots import pyplot

    plt = pyplot()
    written = []

    def plain_log(ax):
        """A log y axis labelled with plain numbers."""
        from matplotlib.ticker import NullFormatter, ScalarFormatter

        ax.set_yscale("log")
        ax.yaxis.set_major_formatter(ScalarFormatter())
        ax.yaxis.set_minor_formatter(NullFormatter())

    def save(fig, filename):
        fig.tight_layout()
        io.save_figure(fig, args.out / filename, comm)
        plt.close(fig)
        written.append(filename)

    # Fig. 7.9
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.3))
    contour(a, "fig7_9", "alpha", "beta", "F_tilde", r"$\tilde F$", lines=[(0.8, "-")])
    plain_log(a)
    a.set_title(r"(a) $\tilde F$ at full closure; black: $\tilde F = 0.8$ ('good' above)", fontsize=9)
    for beta in sorted({r["beta"] for r in ok("fig7_9")}):
        rows = sorted((r for r in ok("fig7_9") if r["beta"] == beta), key=lambda r: r["alpha"])
        b.plot([r["alpha"] for r in rows], [r["preload"] for r in rows], "-o", ms=4, label=rf"$\beta$ = {beta:g}")
    b.plot([1.0], [DISSERTATION["fig7_9b_eps_m_hemisphere"]], "k*", ms=10, label="dissertation, hemisphere")
    b.set_xlabel(r"$\alpha = b/a$")
    b.set_ylabel(r"$\varepsilon_m$")
    b.legend(fontsize=7)
    b.grid(alpha=0.3)
    b.set_title(r"(b) minimum preload for closure $\varepsilon_m$ (independent of $\beta$)", fontsize=9)
    save(fig, "fig7_9.png")

    # Figs. 7.10 and 7.12: frames
    def frames(cases, columns, title, filename, extent):
        fig, axes = plt.subplots(len(cases), len(columns), figsize=(2.3 * len(columns), 2.4 * len(cases)),
                                 squeeze=False)
        for axrow, (label, (summary, rec)) in zip(axes, cases):
            for ax, (stage, which) in zip(axrow, columns):
                state = which(rec) if callable(which) else crater_frames.nearest(rec.states, stage, which)
                crater_frames.draw(ax, rec, state, extent, text=f"{stage} $\\varepsilon$={state['eps']:.3f}")
                ax.set_xticks([])
                ax.set_yticks([])
            axrow[0].set_ylabel(label, fontsize=8)
        fig.suptitle(title, fontsize=10)
        save(fig, filename)

    tried_7_10 = list(shapes_7_10) + [key for key in failed_shapes if key in SHAPES_7_10 + QUICK_SHAPES["7_10"]]
    if tried_7_10:  # rows: beta, columns: alpha
        alphas = sorted({a for a, _ in tried_7_10})
        betas = sorted({b for _, b in tried_7_10})
        fig, axes = plt.subplots(len(betas), len(alphas), figsize=(2.6 * len(alphas), 2.5 * len(betas)),
                                 squeeze=False)
        for alpha, beta in tried_7_10:
            ax = axes[betas.index(beta), alphas.index(alpha)]
            if (alpha, beta) in shapes_7_10:
                summary, rec = shapes_7_10[(alpha, beta)]
                crater_frames.draw(ax, rec, rec.states[-1], 8.0,
                                   text=f"α={alpha:g}, β={beta:g}\nF~={summary['F_tilde']:.2f}")
            else:  # a failed cycle keeps its panel, with the reason
                ax.text(0.5, 0.5, f"α={alpha:g}, β={beta:g}\nno result:\n"
                        + textwrap.fill(str(failed_shapes[(alpha, beta)]), 34),
                        transform=ax.transAxes, ha="center", va="center", fontsize=6, color="tab:red")
            ax.set_xticks([])
            ax.set_yticks([])
        fig.suptitle("Fig. 7.10: craters after complete unloading from full closure (dotted: at rest)", fontsize=10)
        save(fig, "fig7_10.png")
    if types_7_12:
        def unloading_frame(fraction):
            def pick(rec):
                part = [s for s in rec.states if s["stage"] == "unload"]
                return part[min(len(part) - 1, int(fraction * (len(part) - 1)))]
            return pick

        cases = [(f"({tag}) α'={TYPES_7_12[tag][0]:g}, β'={TYPES_7_12[tag][1]:g}\nF~={s['F_tilde']:.2f}, "
                  f"{s['stability']}", (s, rec)) for tag, (s, rec) in types_7_12.items()]
        frames(cases, [("load", 0.0), ("load", 0.2), ("load", lambda rec: [s for s in rec.states
                                                                            if s["stage"] == "load"][-1]),
                       ("unload", unloading_frame(0.33)), ("unload", unloading_frame(0.67)),
                       ("unload", lambda rec: rec.states[-1])],
               "Fig. 7.12: reinforced hemispheres (α = β = 1): ε = 0, 0.2, ε_m, unloading, zero force "
               "(red: the layer)", "fig7_12.png", 8.0)

    # Fig. 7.11
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.3))
    for r in results.get("fig7_11b", []):
        colour = STABILITY_COLOURS.get(r.get("stability_waves"), "0.6")
        a.scatter(r["layer_thickness"], r["layer_stiffness"], s=260, c=colour, marker="s" if r["status"] == "ok"
                  else "x")
        if on_saddle(r):
            a.scatter(r["layer_thickness"], r["layer_stiffness"], s=420, marker="s", facecolors="none",
                      edgecolors="r", linewidths=1.5)
        if still_open("fig7_11b", r):
            a.scatter(r["layer_thickness"], r["layer_stiffness"], s=620, marker="s", facecolors="none",
                      edgecolors="orange", linewidths=1.5)
        if r["status"] == "ok":
            a.annotate(f"{r['F_tilde']:.2f}", (r["layer_thickness"], r["layer_stiffness"]), ha="center",
                       va="center", fontsize=6.5, color="w", weight="bold" if r["F_tilde"] > 1 else "normal")
    low, high = DISSERTATION["fig7_11b_F_above_1"]["layer_thickness"], \
        DISSERTATION["fig7_11b_F_above_1"]["layer_stiffness"]
    a.add_patch(plt.Rectangle((low[0], high[0]), low[1] - low[0], high[1] - high[0], fill=False, ec="gold", lw=2))
    for label, colour in STABILITY_COLOURS.items():
        a.scatter([], [], c=colour, marker="s", label=label)
    a.plot([], [], color="gold", lw=2, label="dissertation: F~ > 1")
    a.scatter([], [], s=80, marker="s", facecolors="none", edgecolors="r", label="ends on a saddle")
    a.scatter([], [], s=80, marker="s", facecolors="none", edgecolors="orange",
              label=f"open at eps = {crater.MAX_CLOSURE_PRELOAD}")
    plain_log(a)
    a.set_xlabel(r"$\alpha' = t/a$")
    a.set_ylabel(r"$\beta' = \mu_l/\mu$")
    a.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    a.set_title(r"(b) symmetry breaking ($n$ = 1..20) at $\alpha = \beta = 1$ (numbers: $\tilde F$, bold > 1)",
                fontsize=9)
    curve(b, "fig7_11c", "alpha", "F_tilde", r"reinforced $\alpha'$ = 0.03, $\beta'$ = 30")
    plain = sorted((r for r in ok("fig7_9") if r["beta"] == 1.0), key=lambda r: r["alpha"])
    b.plot([r["alpha"] for r in plain], [r["F_tilde"] for r in plain], "-s", ms=4, label="unreinforced")
    peak = DISSERTATION["fig7_11c_peak"]
    b.plot([peak["alpha"]], [peak["F_tilde"]], "k*", ms=10, label="dissertation peak")
    opt = DISSERTATION["fig7_9_optimum_beta1"]
    b.plot([opt["alpha"]], [opt["F_tilde"]], "k^", ms=8, label="dissertation unreinforced optimum")
    b.set_xlabel(r"$\alpha$")
    b.set_ylabel(r"$\tilde F$ (full closure, $\beta = 1$)")
    b.legend(fontsize=7)
    b.grid(alpha=0.3)
    b.set_title("(c) reinforced against unreinforced", fontsize=9)
    save(fig, "fig7_11.png")

    # Fig. 8.4
    fig, axes = plt.subplots(1, 4, figsize=(15, 3.6))
    for ax, (key_of, label) in zip(axes, [(lambda r: 1 - r["V2_over_V0"], r"$(V_0 - V_2)/V_0$"),
                                          (lambda r: 1 - r["p2_over_pa"], r"$-\Delta p/p_a$"),
                                          (lambda r: r["A2_over_A0"], r"$A_2/A_0$"),
                                          (lambda r: r["F_tilde"], r"$\tilde F$")]):
        for name, style in (("fig8_4_air", "-s"), ("fig8_4", "-o")):
            rows = sorted(ok(name), key=lambda r: r["preload"])
            ax.plot([r["preload"] for r in rows], [key_of(r) for r in rows], style, ms=4,
                    label="air" if name.endswith("air") else "liquid")
        ax.axvline(DISSERTATION["fig8_4_liquid_eps_c"], color="C1", ls="--", lw=1)
        ax.set_xlabel(r"$\varepsilon$")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle("Fig. 8.4: hemisphere, air against liquid (dashed: the dissertation's non-axisymmetric "
                 "liquid $\\varepsilon_c$ = 0.33)", fontsize=10)
    save(fig, "fig8_4.png")

    # Figs. 8.6b and 8.7
    fig, axes = plt.subplots(2, 3, figsize=(15, 8.2))
    contour(axes[0, 0], "fig8_6b", "alpha", "preload", "F_hat", r"$\hat F$")
    axes[0, 0].set_title(r"8.6b: $\hat F(\alpha, \varepsilon)$, unreinforced", fontsize=9)
    curve(axes[0, 1], "fig8_7b_plain", "alpha", "F_hat", "unreinforced")
    curve(axes[0, 1], "fig8_7b_layer", "alpha", "F_hat", r"$\alpha'$ = 0.03, $\beta'$ = 30")
    for kind, marker in (("plain", "k^"), ("layer", "k*")):
        p = DISSERTATION["fig8_7b_peaks"][kind]
        axes[0, 1].plot([p["alpha"]], [p["F_hat"]], marker, ms=9, label=f"dissertation peak ({kind})")
    axes[0, 1].set_xlabel(r"$\alpha$")
    axes[0, 1].set_ylabel(r"$\hat F$")
    axes[0, 1].legend(fontsize=7)
    axes[0, 1].grid(alpha=0.3)
    axes[0, 1].set_title(r"8.7b: $\varepsilon$ = 0.25", fontsize=9)
    contour(axes[0, 2], "fig8_7c", "alpha", "preload", "F_hat", r"$\hat F$")
    axes[0, 2].set_title(r"8.7c: $\alpha'$ = 0.03, $\beta'$ = 30", fontsize=9)
    contour(axes[1, 0], "fig8_7d", "alpha", "preload", "F_hat", r"$\hat F$")
    axes[1, 0].set_title(r"8.7d: $\alpha'$ = 0.05, $\beta'$ = 100", fontsize=9)
    for ax, name, group, fixed in ((axes[1, 1], "fig8_7e", "layer_thickness", r"$\varepsilon$ = 0.4"),
                                   (axes[1, 2], "fig8_7f", "preload", r"$\alpha'$ = 0.05")):
        for value in sorted({r[group] for r in ok(name)}):
            rows = sorted((r for r in ok(name) if r[group] == value), key=lambda r: r["layer_stiffness"])
            ax.plot([r["layer_stiffness"] for r in rows], [r["F_hat"] for r in rows], "-o", ms=4,
                    label=f"{group} = {value:g}")
        ax.set_xscale("log")
        ax.set_xlabel(r"$\beta'$")
        ax.set_ylabel(r"$\hat F$")
        ax.grid(alpha=0.3)
        if ax.lines:
            ax.legend(fontsize=7)
        ax.set_title(f"8.7{'e' if name.endswith('e') else 'f'}: hemisphere, {fixed}", fontsize=9)
    fig.suptitle(r"Liquid-filled craters: $\hat F = -\Delta p A_2/(\mu A_0)$ (0 where the crater closed on "
                 "loading, eq. 8.8)", fontsize=10)
    save(fig, "fig8_6_8_7.png")
    report("wrote " + ", ".join(str(args.out / f) for f in written + ["crater_design.csv", "summary.json"]))

# %% [markdown]
# ## Assert
#
# 1. Every point and every shape cycle converges, on the quick grid and on the
#    full one (a failed point is still written, listed in `summary.json` and drawn
#    as a cross before this fails the run).
# 2. Stage 1 with the vent open is independent of $\beta$ (no pressure
#    difference acts on the wall, and the regulariser scales with $\mu$): the
#    closure strain $\varepsilon_m$ of every $\alpha$ is the same for every
#    $\beta$, to the bisection's resolution.
# 3. A crater closed on loading unloads with a vacuum: $p_2 = 0$ and
#    $\tilde F = A_2/A_0$ (eq. 7.17); a liquid keeps its volume,
#    $V_2 = V_1$, and gives $\hat F = 0$ where it closed (eq. 8.8).
# 4. A stiffer specimen recovers more of its crater: at every $\alpha$,
#    $A_2/A_0$ does not decrease from $\beta = 1$ to $\beta = 5$.

# %%
assert not shape_failures, shape_failures
assert all(r["status"] == "ok" for rows in results.values() for r in rows), \
    [(name, r["reason"]) for name, rows in results.items() for r in rows if r["status"] != "ok"]
resolution = AIR.strain_step * 2.0 ** -9
for alpha in {r["alpha"] for r in ok("fig7_9")}:
    eps_m = [r["preload"] for r in ok("fig7_9") if r["alpha"] == alpha]
    assert max(eps_m) - min(eps_m) <= resolution, (alpha, eps_m)
for name, rows in results.items():
    base = MAPS[name][0]
    for r in (r for r in rows if r["status"] == "ok"):
        closed = r["V1_over_V0"] <= CLOSED
        if base.fluid == "air" and closed:
            assert r["p2_over_pa"] == 0.0 and abs(r["F_tilde"] - r["A2_over_A0"]) < 1e-12, (name, r)
        if base.fluid == "liquid":
            assert abs(r["V2_over_V0"] - r["V1_over_V0"]) < 1e-8, (name, r)
            if closed:
                assert r["F_hat"] == 0.0, (name, r)
by = {(r["alpha"], r["beta"]): r for r in ok("fig7_9")}
for (alpha, beta), r in by.items():
    if beta == 1.0 and (alpha, 5.0) in by:
        assert by[(alpha, 5.0)]["A2_over_A0"] >= r["A2_over_A0"] - 1e-3, (alpha, r, by[(alpha, 5.0)])
report("checks passed: points converge, eps_m independent of beta, vacuum and liquid laws, "
       "stiffer specimens recover more area")
