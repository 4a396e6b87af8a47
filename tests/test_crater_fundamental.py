"""The crater's fundamental branch (``--path fundamental``): arc-length in the platen displacement."""

from __future__ import annotations

import gc

from mpi4py import MPI

import numpy as np
import pytest
from helpers import same_loads

from bcfem.run.runner import SolveError
from bcfem.scenes import crater

COARSE = dict(size_crater=0.12)
PATH_KEYS = ("V1_over_V0", "V2_over_V0", "p2_over_pa", "A2_over_A0", "F_tilde", "eps_at_zero_force")


def test_the_branch_is_the_stepped_path_where_that_is_stable():
    """Up to eps = 0.2 the hemisphere is stable: arc-length in the platen reaches the same
    states as load stepping with the platen as a Dirichlet value, to solver tolerance, in
    both stages (the unloading branch from 0.2 included)."""
    _, stepped = crater.solve(crater.Params(preload=0.2, **COARSE), MPI.COMM_WORLD)
    rows, traced = crater.solve(crater.Params(preload=0.2, path="fundamental", **COARSE), MPI.COMM_WORLD)
    assert stepped["stability"] == traced["stability"] == "stable"
    assert all(r["unstable"] == 0 for r in rows) and traced["folds"] == []
    assert rows[0]["eps"] == 0 and max(r["eps"] for r in rows) == pytest.approx(0.2, abs=1e-9)
    for key in PATH_KEYS:
        # the zero-force strain is located to the event tolerance (1e-9 in arc length)
        assert traced[key] == pytest.approx(stepped[key], rel=1e-7, abs=2e-9), key
    # the last row is the zero-force state
    assert abs(rows[-1]["platen_force"]) < 1e-8 and traced["F_tilde"] > 0.05


def traced(params, comm) -> tuple[list[dict], dict, str | None]:
    """The rows and results of a fundamental run, also of one whose branch ends (a result:
    the error says where). The error's traceback holds the model in reference cycles: they
    are collected here, on every rank at once, since a collection at another time on each
    rank destroys the model's distributed objects out of step (a crash in a later test)."""
    try:
        rows, summary = crater.solve(params, comm)
        outcome = rows, summary, None
    except SolveError as error:
        outcome = error.run.rows, error.run.results, str(error)
    gc.collect()
    return outcome


@pytest.mark.slow
def test_every_fold_in_eps_changes_the_count_by_one():
    """Under displacement control an eigenvalue of the tangent at fixed platen crosses zero
    where the branch turns back in eps: the unstable counts of the points on either side of
    each fold differ by exactly one. Loading this crater snaps back at eps ~ 0.34 (a maximum,
    then a minimum of eps) before it reaches 0.36. (A change without a fold is a bifurcation.)"""
    rows, results, _ = traced(crater.Params(preload=0.36, path="fundamental", **COARSE), MPI.COMM_WORLD)
    folds = [f for f in results["folds"] if f["stage"] == "load"]
    assert [f["kind"] for f in folds] == ["eps_max", "eps_min"], folds
    assert 0.33 < folds[1]["eps"] < folds[0]["eps"] < 0.35
    load = [r for r in rows if r["stage"] == "load"]
    assert load[-1]["eps"] == pytest.approx(0.36, abs=1e-9)
    for fold in results["folds"]:
        part = [r for r in rows if r["stage"] == fold["stage"]]
        after = int(np.searchsorted([r["s"] for r in part], fold["s"]))
        assert abs(part[after]["unstable"] - part[after - 1]["unstable"]) == 1, fold
    # the stretch between the folds is unstable, the branch on either side stable
    between = [r for r in load if folds[0]["s"] < r["s"] < folds[1]["s"]]
    assert between and all(r["unstable"] == 1 for r in between)
    assert all(r["unstable"] == 0 for r in load if r["s"] < folds[0]["s"] or r["s"] > folds[1]["s"])


@pytest.mark.mpi
@pytest.mark.slow
def test_two_ranks_trace_the_serial_branch():
    """Both stages from eps = 0.2, short of the first fold (0.34): every point equal on the
    world communicator and on one rank. (A world run that ended with an error left the
    ranks out of step for later tests, so this one stays where the unloading branch reaches
    zero force: from 0.225 on it does not.)"""
    params = crater.Params(preload=0.2, path="fundamental", **COARSE)
    world, world_results, world_end = traced(params, MPI.COMM_WORLD)
    alone, alone_results, alone_end = traced(params, MPI.COMM_SELF)
    assert world_end is None and alone_end is None, (world_end, alone_end)
    assert world_results["folds"] == alone_results["folds"] == []
    # the points at the same arc length, and each stage's end (eps = 0.2, zero force), located
    # whatever the steps (which a Newton iteration count, round-off's, may change)
    ends = [tuple([r for r in rows if r["stage"] == stage][-1] for rows in (world, alone))
            for stage in ("load", "unload")]
    pairs = same_loads(world, alone, "s") + ends
    assert pairs[0][0] is world[0] and {a["stage"] for a, _ in pairs} == {"load", "unload"}
    for a, b in pairs:
        assert a["unstable"] == b["unstable"] and a["stage"] == b["stage"]
        for key in ("eps", "V_over_V0", "A_over_A0", "F_tilde", "platen_force"):
            assert a[key] == pytest.approx(b[key], rel=1e-8, abs=1e-10), key


def test_bad_path_is_refused():
    with pytest.raises(ValueError, match="path must be one of"):
        crater.Params(path="relaxed")
