"""The scene ``crater-sector`` for the runner: the wedge's cycle (stages ``load`` and ``unload``)
or its drawn path (stage ``drawn``: the fundamental branch to the first onset, then the
bifurcated one), as rows of ``branch.csv`` and entries of ``summary.json``."""

from __future__ import annotations

from bcfem.path.terminations import Reaches
from bcfem.run.stages import Scene
from bcfem.scenes.crater_sector import paths
from bcfem.scenes.crater_sector.params import Params, columns


class SectorScene(Scene):
    """``crater-sector``; its stages are the drive's."""

    params: Params
    name = "crater-sector"

    def __init__(self, params: Params, comm, extra_terms=()):
        self.params, self.comm, self.extra_terms = params, comm, tuple(extra_terms)
        self.stages = ("load", "unload") if params.drive == "cycle" else ("drawn", "wave")
        self.columns = columns(params.drive)

    def solve(self, run) -> None:
        p = self.params
        # every problem is the run's: its options, Newton counts and timings are in summary.json
        common = dict(beta=p.beta, kappa_ratio=p.kappa_ratio, sector=p.geometry(), comm=self.comm,
                      extra_terms=self.extra_terms, open_problem=run.stage)
        if p.drive == "cycle":
            rows = paths.cycle(p.preload, steps=p.steps, **common)
            for row in rows:
                run.record(row)
            run.stages += [{"stage": "load", "until": str(Reaches("eps", p.preload)), "ended": "preloaded"},
                           {"stage": "unload", "until": str(Reaches("eps", 0.0, falling=True)),
                            "ended": f"eps = {rows[-1]['eps']:g}"}]
            loaded = [r for r in rows if r["stage"] == "load"][-1]
            run.results.update(V1_over_V0=loaded["V_over_V0"], p_end_over_pa=rows[-1]["p_over_pa"],
                               F_tilde_at_eps_0=rows[-1]["F_tilde"])
            return
        m = p.wedge_waves
        found = paths.drawn_stability(p.drawn(), layer_stiffness=p.layer_stiffness, bisections=p.bisections,
                                      amplitudes=p.amplitudes(), **common)
        for r, unstable, s in sorted(found["rows"]):
            run.record({"stage": "drawn", "branch": "fundamental", "r": r, "s": s, "unstable": unstable})
        onset = found["onset"]
        drawn_max = max(p.drawn())
        run.stages.append({"stage": "drawn", "until": f"the first onset, or r = {drawn_max:g}",
                           "ended": found["failure"] or (f"onset at r in [{onset[0]:.6g}, {onset[1]:.6g}]" if onset
                                                         else f"no onset up to r = {drawn_max:g}")})
        suction = {r: s for r, _, s in found["rows"]}
        run.results.update(onset=None if onset is None else {
            "r_stable": onset[0], "r_unstable": onset[1], "s_stable": suction[onset[0]],
            "s_unstable": suction[onset[1]]}, failure=found["failure"])
        if "branch" not in found:
            return
        n = found["waves"]
        run.stages.append({"stage": "wave", "until": "the wave's branch ends", "ended": found["branch_failure"]
                           or f"the {n}-wave branch is followed over {len(found['branch'])} points"})
        post = []
        for row in found["branch"]:
            c = row["fourier"]
            entry = {"stage": "drawn", "branch": f"n={n}", "r": row["r"], "s": row["s"],
                     "A_over_A0": row["A_over_A0"], "F_tilde": row["F_tilde"], "unstable": row["unstable"],
                     "c_0": c[0], "c_m": c[m], "c_2m": c[2 * m]}
            run.record(entry)
            post.append(entry)
        run.results.update(critical_mode={"waves": n, "eigenvalue": found["mode"]["mu"],
                                          "fourier": {str(k): v for k, v in found["mode"]["fourier"].items()}},
                           post_buckled=post, branch_failure=found["branch_failure"],
                           post_buckled_stable_from_r=min((e["r"] for e in post if e["unstable"] == 0), default=None))
