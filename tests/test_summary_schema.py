"""One ``summary.json`` schema for every scene: the runner's record of any scene's solve has the
same keys, with the counts of the problems the scene solved (a scene that built its problems
outside the run would show no Newton iterations, options or dofs)."""

from mpi4py import MPI

import pytest

from bcfem.run.runner import solve
from bcfem.run.summary import time_split
from bcfem.scenes import REGISTRY
from bcfem.solver.problem import TIMED

SCHEMA = {"scene", "status", "error", "parameters", "stages", "steps", "newton_solves", "newton_iterations",
          "failed_solves", "null_pivots", "dofs", "ranks", "wall_time_s", "time_split_s", "jit", "versions",
          "petsc_options", "columns", "peak_rss_mb"}
#: a small run of each scene
SMALL = {
    "blister-rigid": dict(cells=20, v_max=0.5),
    "crater-sector": dict(drive="drawn", wedge_waves=8, drawn_max=0.01, drawn_step=0.005),
    "blister-3d": dict(size=0.25, v_max=0.5),
    "blister-soft": dict(v_max=0.3),
    "droplet-soft": dict(size_contact=0.05, width=3),
    "crater": dict(preload=0.05, size_crater=0.2, strain_step=0.05),
    "crater-cell": dict(crater_radius=1.0, specimen_height=10.0, filling=0.01, size_wall=0.5, size_far=5.0,
                        preload=0.05, strain_step=0.05),
    "crater-double": dict(protuberance_radius=0.0, seal="preload", plate="frictionless", size_wall=0.16,
                          size_contact=0.04, specimen_radius=3.0, specimen_height=3.0, preload=0.05,
                          strain_step=0.025),
}
FAST = {"blister-rigid", "crater-sector"}
#: declared columns a small run does not reach: the sector's bifurcated branch (it stops at the onset)
UNREACHED = {"crater-sector": {"A_over_A0", "F_tilde", "c_0", "c_m", "c_2m"}}


def test_every_scene_has_a_small_run():
    assert set(SMALL) == set(REGISTRY)


@pytest.mark.parametrize("scene", [pytest.param(s, marks=() if s in FAST else pytest.mark.slow) for s in SMALL])
def test_a_scenes_summary_has_the_schema(scene):
    module = REGISTRY[scene]
    run, summary = solve(module.build(module.Params(**SMALL[scene]), MPI.COMM_WORLD), MPI.COMM_WORLD)
    assert SCHEMA <= set(summary), SCHEMA - set(summary)
    assert summary["status"] == "ok" and summary["steps"] == len(run.rows) > 0
    assert summary["newton_iterations"] >= summary["newton_solves"] > 0 and summary["dofs"] > 0
    assert summary["null_pivots"] == 0
    # the declared columns are what the rows hold, with their units
    written = {key for r in run.rows for key in r}
    declared = [c["name"] for c in summary["columns"]]
    assert set(declared) - UNREACHED.get(scene, set()) <= written, set(declared) - written
    assert all(c["unit"] is not None and c["meaning"] for c in summary["columns"])
    # every stage's problem says what ended it (a staged scene's stages in the order they ran)
    assert summary["stages"] and all(s["stage"] in run.scene.stages and s["until"] and ("ended" in s or "skipped" in s)
                                     for s in summary["stages"])
    assert list(summary["time_split_s"]) == list(time_split(dict.fromkeys(TIMED, 0.0), 0.0))
    # every rank's peak memory: at least the interpreter with dolfinx loaded, and not a unit off
    assert len(summary["peak_rss_mb"]) == MPI.COMM_WORLD.size and all(50 < m < 50_000 for m in summary["peak_rss_mb"])
    prefix = f"bcfem_{scene}_".replace("-", "_")
    assert summary["petsc_options"] and all(k.startswith(prefix) for k in summary["petsc_options"])
