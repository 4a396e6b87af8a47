"""The crater's fundamental branch (``--path fundamental``): arc-length in the platen displacement."""

from __future__ import annotations

from mpi4py import MPI

import numpy as np
import pytest

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


@pytest.mark.slow
def test_every_fold_in_eps_changes_the_count_by_one():
    """Under displacement control an eigenvalue of the tangent at fixed platen crosses zero
    where the branch turns back in eps: the unstable counts of the points on either side of
    each fold differ by exactly one. Unloading this air crater from near closure snaps back
    (two folds). (A count that changes without a fold is a bifurcation.)"""
    rows, summary = crater.solve(crater.Params(preload=0.41, path="fundamental", **COARSE), MPI.COMM_WORLD)
    kinds = [f["kind"] for f in summary["folds"]]
    assert kinds == ["eps_min", "eps_max"], summary["folds"]
    for fold in summary["folds"]:
        part = [r for r in rows if r["stage"] == fold["stage"]]
        after = int(np.searchsorted([r["s"] for r in part], fold["s"]))
        assert abs(part[after]["unstable"] - part[after - 1]["unstable"]) == 1, fold
    lower, upper = (f["eps"] for f in summary["folds"])
    assert lower < upper  # a snap-back: eps falls to a minimum, then rises again


@pytest.mark.slow
def test_the_branch_closes_and_a_closed_crater_unloads_under_vacuum():
    rows, summary = crater.solve(crater.Params(preload=crater.PRELOAD_TO_CLOSURE, path="fundamental", **COARSE),
                                 MPI.COMM_WORLD)
    load = [r for r in rows if r["stage"] == "load"]
    assert summary["eps_m"] == load[-1]["eps"] and 0.38 < summary["eps_m"] < 0.45
    assert summary["V1_over_V0"] == pytest.approx(1e-3, rel=1e-6)  # located on the closure criterion
    assert all(a["eps"] < b["eps"] for a, b in zip(load, load[1:]))  # no fold on loading
    # vacuum: F = p_a A2 at zero platen force
    assert summary["p2_over_pa"] == 0 and summary["F_tilde"] == pytest.approx(summary["A2_over_A0"])
    assert abs(rows[-1]["platen_force"]) < 1e-8


@pytest.mark.mpi
@pytest.mark.slow
def test_two_ranks_trace_the_serial_branch():
    """Through the first loss of stability (eps ~ 0.36 on this mesh) to eps = 0.38: every
    point equal on the world communicator and on one rank."""
    params = crater.Params(preload=0.38, path="fundamental", **COARSE)
    world, _ = crater.solve(params, MPI.COMM_WORLD)
    alone, _ = crater.solve(params, MPI.COMM_SELF)
    assert len(world) == len(alone) and any(r["unstable"] > 0 for r in world)
    for a, b in zip(world, alone):
        assert a["unstable"] == b["unstable"]
        for key in ("eps", "V_over_V0", "A_over_A0", "F_tilde", "platen_force"):
            assert a[key] == pytest.approx(b[key], rel=1e-8, abs=1e-10), key


def test_bad_path_is_refused():
    with pytest.raises(ValueError, match="path must be one of"):
        crater.Params(path="relaxed")
