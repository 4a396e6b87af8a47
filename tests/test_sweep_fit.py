"""Sweeps (rank-count invariant, resumable, failures kept) and the inverse fit."""


import json
from dataclasses import replace

from mpi4py import MPI

import numpy as np
import pytest
from helpers import bcfem, on_ranks, refused

from bcfem.run import sweep
from bcfem.scenes import blister_rigid, blister_studies

GRID = ["sweep", "blister-rigid", "--grid", "alpha=0:2:2", "--grid", "adhesion=1:4:2",
        "--material", "gent", "--v-max", "20", "--cells", "30", "--quiet"]


@pytest.mark.slow
def test_sweep_is_rank_count_invariant_and_resumable(tmp_path):
    serial, parallel = tmp_path / "serial", tmp_path / "mpi"
    res = bcfem(*GRID, "--out", str(serial))
    assert res.returncode == 0, res.stderr
    res = bcfem(*GRID, "--out", str(parallel), ranks=2)
    assert res.returncode == 0, res.stderr
    assert (serial / "sweep.csv").read_text() == (parallel / "sweep.csv").read_text()
    assert (serial / "maps.png").stat().st_size > 10_000
    rows = sweep_rows(serial)
    assert len(rows) == 4 and all(r["status"] == "ok" for r in rows)
    # a rerun solves nothing and rewrites the same map
    stamp = {p.name: p.stat().st_mtime_ns for p in (serial / "points").iterdir()}
    res = bcfem(*GRID[:-1], "--out", str(serial))
    assert "0 points solved, 4 reused" in res.stderr
    assert stamp == {p.name: p.stat().st_mtime_ns for p in (serial / "points").iterdir()}
    # the ranks' claims on points are cleared at the end of a run
    assert not list((parallel / "points").glob(".claims-*")) and not list((serial / "points").glob(".claims-*"))


def sweep_rows(out):
    from bcfem.io import read_csv

    return read_csv(out / "sweep.csv")


def test_a_failed_point_is_recorded_not_dropped(tmp_path):
    base = blister_rigid.Params()
    points = sweep.grid_points(base, [("alpha", [0.0, 1.0, 2.0])])

    def solve(params, comm):
        if params.alpha == 1.0:
            raise RuntimeError("solver gave up")
        return {"value": params.alpha * 2}

    rows = sweep.run(points, solve, tmp_path, MPI.COMM_WORLD)
    assert [r["status"] for r in rows] == ["ok", "failed", "ok"]
    assert "solver gave up" in rows[1]["reason"]
    assert rows[2]["value"] == 4.0
    # a rerun keeps the recorded failure; --retry-failed solves it again (and only it)
    calls = []

    def fixed(params, comm):
        calls.append(params.alpha)
        return {"value": params.alpha * 2}

    assert [r["status"] for r in sweep.run(points, fixed, tmp_path, MPI.COMM_WORLD)] == ["ok", "failed", "ok"]
    assert calls == []
    rows = sweep.run(points, fixed, tmp_path, MPI.COMM_WORLD, retry_failed=True)
    assert [r["status"] for r in rows] == ["ok", "ok", "ok"] and calls == [1.0] and rows[1]["value"] == 2.0


def test_a_larger_budget_retries_only_the_points_that_ran_out(tmp_path):
    """Solver budgets (fields marked ``budget``) stay out of a point's key: a solved point is
    reused whatever the budget; a failed one is solved again once the budget has grown."""
    from bcfem.scenes import crater

    def points(max_snaps):
        return sweep.grid_points(crater.Params(max_snaps=max_snaps), [("alpha", [0.5, 1.0])])

    calls = []

    def solve(params, comm):
        calls.append((params.alpha, params.max_snaps))
        if params.alpha == 1.0 and params.max_snaps < 10:
            raise RuntimeError(f"more than {params.max_snaps} snaps")
        return {"value": params.alpha}

    assert [r["status"] for r in sweep.run(points(6), solve, tmp_path, MPI.COMM_WORLD)] == ["ok", "failed"]
    assert [sweep.point_key({"alpha": 1.0}, p) for _, p in points(6)] == \
        [sweep.point_key({"alpha": 1.0}, p) for _, p in points(24)]
    for budget in (6, 3):  # the same or a smaller budget: nothing to gain
        assert [r["status"] for r in sweep.run(points(budget), solve, tmp_path, MPI.COMM_WORLD)] == ["ok", "failed"]
    assert calls == [(0.5, 6), (1.0, 6)]
    rows = sweep.run(points(24), solve, tmp_path, MPI.COMM_WORLD)
    assert [r["status"] for r in rows] == ["ok", "ok"] and calls[2:] == [(1.0, 24)]
    assert "budgets" not in (tmp_path / "sweep.csv").read_text() and rows[1]["solve_time_s"] >= 0


SLOW_FIRST = """
import json, sys, time
from mpi4py import MPI
from bcfem.run import sweep
from bcfem.scenes import blister_rigid

def solve(params, comm):
    time.sleep(3.0 if params.alpha == 0 else 0.2)  # the first point is slow
    return {"rank": MPI.COMM_WORLD.rank}

rows = sweep.run(sweep.grid_points(blister_rigid.Params(), [("alpha", [0.0, 1.0, 2.0, 3.0, 4.0])]), solve,
                 sys.argv[1], MPI.COMM_WORLD)
if MPI.COMM_WORLD.rank == 0:
    print(json.dumps([r["rank"] for r in rows]))
"""


def _on_two_ranks(script_text: str, tmp_path):
    """Run ``script_text`` (argument: an output directory, ``tmp_path/out``) on 2 ranks; the
    JSON of its last line of output."""
    import subprocess
    import sys

    script = tmp_path / "script.py"
    script.write_text(script_text)
    res = subprocess.run(on_ranks([sys.executable, str(script), str(tmp_path / "out")], 2),
                         capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr
    return json.loads(res.stdout.strip().splitlines()[-1])


def test_points_go_to_the_rank_that_is_free(tmp_path):
    """On 2 ranks, the rank that took a slow first point solves nothing else: the other
    rank takes every later point as it becomes free (a fixed round-robin would have given
    the slow rank every other point)."""
    ranks = _on_two_ranks(SLOW_FIRST, tmp_path)
    assert ranks[0] not in ranks[1:] and len(set(ranks[1:])) == 1, ranks


SLOW_LAST_THEN_ANOTHER = """
import json, sys, time
from pathlib import Path
from mpi4py import MPI
from bcfem.run import sweep
from bcfem.scenes import blister_rigid

def solve(params, comm):
    time.sleep(1.5 if params.alpha == 2 else 0.05)  # the first sweep's last point is slow
    return {"rank": MPI.COMM_WORLD.rank}

out = Path(sys.argv[1])
grid = lambda values: sweep.grid_points(blister_rigid.Params(), [("alpha", values)])
first, second = sweep.run_pool([(grid([0.0, 1.0, 2.0]), solve, out / "first"),
                                (grid([3.0, 4.0, 5.0, 6.0]), solve, out / "second")], MPI.COMM_WORLD)
if MPI.COMM_WORLD.rank == 0:
    print(json.dumps([[r["rank"] for r in first], [r["rank"] for r in second]]))
"""


def test_a_pool_of_sweeps_keeps_every_rank_busy(tmp_path):
    """On 2 ranks, while one rank solves the slow last point of the first sweep, the other
    goes on to the second and solves all of it (separate runs would wait for the slow
    point and then share the second sweep); each sweep gets its own CSV and timing."""
    first, second = _on_two_ranks(SLOW_LAST_THEN_ANOTHER, tmp_path)
    slow_rank = first[2]
    assert slow_rank not in second, (first, second)
    for name, points in (("first", 3), ("second", 4)):
        timing = json.loads((tmp_path / "out" / name / "timing.json").read_text())
        assert timing["solved"] == points and timing["pooled_sweeps"] == 2 and timing["ranks"] == 2
        assert len(sweep_rows(tmp_path / "out" / name)) == points
    assert json.loads((tmp_path / "out" / "first" / "timing.json").read_text())["point_solve_time_s"] >= 1.5
    assert not list((tmp_path / "out").glob("*/points/.claims-*"))


def test_a_pool_refuses_two_sweeps_in_one_directory(tmp_path):
    """Two sweeps writing to one directory would share their claims: refused before anything
    is solved or written."""
    points = sweep.grid_points(blister_rigid.Params(), [("alpha", [0.0])])
    solved = []
    with pytest.raises(ValueError, match="its own output directory"):
        sweep.run_pool([(points, lambda p, c: solved.append(p) or {}, tmp_path / "a"),
                        (points, lambda p, c: solved.append(p) or {}, tmp_path / "b" / ".." / "a")], MPI.COMM_WORLD)
    assert not solved and not (tmp_path / "a").exists()


def test_maps_of_failed_points_and_one_value_axes(tmp_path):
    """A sweep whose points all failed still draws its maps (blank panels), and an axis
    with one value is a constant: the CLI then draws curves over the other axis."""
    rows = [{"a": a, "b": b, "status": "failed", "reason": "x"} for a in (1.0, 2.0) for b in (3.0, 4.0)]
    sweep.contour_maps(rows, "a", "b", [("F", "F")], "t", tmp_path / "maps.png", MPI.COMM_WORLD)
    assert (tmp_path / "maps.png").stat().st_size > 0
    res = bcfem("sweep", "blister-rigid", "--grid", "alpha=0,1", "--grid", "adhesion=1", "--v-max", "2",
                "--out", tmp_path / "one", "--quiet")
    assert res.returncode == 0, res.stderr
    assert (tmp_path / "one" / "curves.png").exists() and "2 points" in res.stdout


def test_panels_wrap_into_rows_of_at_most_four():
    """A crater sweep's 8 maps are 2 rows of 4 (not one row 5000 px wide), 9 are 3 x 3."""
    from bcfem.plots import pyplot

    plt = pyplot()
    for count, shape in ((1, (1, 1)), (4, (1, 4)), (5, (2, 3)), (8, (2, 4)), (9, (3, 3))):
        fig, panels = sweep._panel_grid(plt, count, 4.2, 3.6)
        grid = fig.axes[0].get_subplotspec().get_gridspec()
        assert (grid.nrows, grid.ncols) == shape and len(panels) == count
        assert [ax for ax in fig.axes if ax.get_visible()] == panels
        plt.close(fig)


def test_a_flag_with_start_stop_step_is_an_axis():
    assert np.allclose(sweep.parse_range("preload", "0:0.5:0.025"), np.linspace(0, 0.5, 21))
    assert np.allclose(sweep.parse_range("alpha", "0.5:1:0.5"), [0.5, 1.0])
    for bad in ("0:0.5:0.3", "0:0.5:0", "1:0:0.1", "0:x:1"):
        with pytest.raises(ValueError, match="alpha"):
            sweep.parse_range("alpha", bad)


def test_bad_grid_exits_2(tmp_path):
    assert "nonsense" in refused("sweep", "blister-rigid", "--grid", "nonsense=1:2:3", out=tmp_path / "x")
    assert "alpha" in refused("sweep", "blister-rigid", "--grid", "alpha=-1:2:3", out=tmp_path / "y")
    assert "alpha" in refused("sweep", "blister-rigid", "--alpha", "0:1:0.3", out=tmp_path / "z")
    assert "no grid axis" in refused("sweep", "blister-rigid", out=tmp_path / "w")
    assert not any((tmp_path / d).exists() for d in "xyzw")


def test_fit_recovers_known_parameters():
    params = blister_rigid.Params(material="gent", Jm=100.0, v_max=30.0, cells=40)
    truth = {"alpha": 1.3, "adhesion": 3.0}
    forward = blister_studies.after_onset(blister_rigid.Params(**{**params.__dict__, **truth}), MPI.COMM_WORLD)
    assert forward["onset"]
    result = blister_studies.solve_fit(forward["aspect1"], forward["P1"], params, MPI.COMM_WORLD,
                                       guess=(1.0, 2.5), tol=1e-12)
    assert result["converged"]
    assert result["alpha"] == pytest.approx(truth["alpha"], abs=1e-6)
    assert result["adhesion"] == pytest.approx(truth["adhesion"], abs=1e-6)


def test_map_points_trace_one_compiled_blister(monkeypatch):
    """Points that differ only in run-time constants (alpha, adhesion) trace one composed
    blister again: their values equal those of a blister composed for each point, and no
    state leaks from one point to the next (A, B, C, A repeats A exactly)."""
    base = blister_rigid.Params(material="gent", Jm=100.0, v_max=30.0, cells=20)
    points = [replace(base, alpha=1.0, adhesion=5.0), replace(base, alpha=3.0, adhesion=10.0),
              replace(base, alpha=0.5, adhesion=15.0)]
    assert blister_rigid.structure(points[0]) == blister_rigid.structure(points[1])
    assert blister_rigid.structure(replace(base, alpha=0.0)) != blister_rigid.structure(points[0])
    sessions = blister_studies.reusing()

    def fresh(params):
        sessions.close()
        return blister_studies.after_onset(params, MPI.COMM_SELF)

    expected = [fresh(p) for p in points]
    sessions.close()
    composed = []
    compose = blister_studies.compose
    monkeypatch.setattr(blister_studies, "compose", lambda *args: composed.append(args) or compose(*args))
    with sessions:
        reused = [blister_studies.after_onset(p, MPI.COMM_SELF) for p in points + points[:1]]
        session = sessions.current
        assert len(composed) == 1 and session.problem is not None
    assert session.problem is None and sessions.current is None  # closed on leaving: PETSc objects destroyed
    assert reused[3] == reused[0]
    for got, want in zip(reused, expected):
        assert got["onset"] and want["onset"]
        for key in blister_studies.MAP_COLUMNS:
            assert got[key[0]] == pytest.approx(want[key[0]], rel=1e-10, abs=0)


def test_a_grid_axis_of_words_sweeps_a_choice():
    from bcfem.scenes import crater_double

    name, words = sweep.parse_axis("contact=separable,bonded")
    assert name == "contact" and words == ["separable", "bonded"]
    axes = [(name, words), sweep.parse_axis("preload=0.02,0.05")]
    points = sweep.grid_points(crater_double.Params(), axes)
    assert [(p.contact, p.preload) for _, p in points] == [("separable", 0.02), ("separable", 0.05),
                                                          ("bonded", 0.02), ("bonded", 0.05)]
    keys = {sweep.point_key(values, params) for values, params in points}
    assert len(keys) == 4 and any("contact=bonded" in k for k in keys)
    with pytest.raises(ValueError, match="contact"):
        sweep.grid_points(crater_double.Params(), [sweep.parse_axis("contact=glued")])
