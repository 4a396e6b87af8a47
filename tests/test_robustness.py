"""Stiff and extreme cases of blister-rigid: each converges or fails with a clear message."""

import json

from mpi4py import MPI

import numpy as np
import pytest
from helpers import bcfem

from bcfem.run.trace import trace
from bcfem.scenes import blister_rigid


def fold(**kwargs):
    scene = blister_rigid.build(blister_rigid.Params(cells=60, **kwargs), MPI.COMM_WORLD)
    branch, problem = trace(scene)
    problem.close()
    return branch


def test_any_surface_tension_converges_and_tends_to_the_droplet():
    """alpha from 0.5 to 1e6: the fold tends to the hemisphere, P = 2 alpha at V/V0 = 1/2."""
    gaps = []
    for alpha in (0.5, 10.0, 1e3, 1e6):
        branch = fold(material="neo-hookean", alpha=alpha, v_max=1.0)
        assert branch.rows[-1]["V_over_V0"] == pytest.approx(1.0, abs=1e-9)
        lp = branch.limit_points[0].values
        gaps.append(abs(lp["P"] / (2 * alpha) - 1))
    assert np.all(np.diff(gaps) < 0)
    assert gaps[-1] < 1e-5


def test_vanishing_membrane_stiffness():
    """mu_f t0 / gamma_l = 1e-7 (the droplet limit), traced through the hemisphere fold."""
    branch = fold(material="neo-hookean", alpha=1.0, stiffness=1e-7, v_max=1.0, v_start=0.05)
    lp = branch.limit_points[0].values
    assert lp["V_over_V0"] == pytest.approx(0.5, rel=1e-6)
    assert lp["P"] == pytest.approx(2.0, rel=1e-6)


def test_gent_locking_fails_with_a_clear_message(tmp_path):
    out = tmp_path / "lock"
    res = bcfem("run", "blister-rigid", "--Jm", "2", "--cells", "30", "--quiet", "--out", out, timeout=300)
    assert res.returncode == 1
    assert "locking" in res.stderr and "Jm" in res.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "failed" and "locking" in summary["error"]
    # the converged part is kept, and it is a rising branch up to near the lock
    rows = (out / "branch.csv").read_text().splitlines()
    assert len(rows) > 10


def test_strong_gent_stiffening_removes_the_n_shape():
    """Jm = 20 locks before the neo-Hookean peak: P rises monotonically, no fold; Jm = 100 has two."""
    stiff = fold(material="gent", Jm=20.0, v_max=3.0)
    assert stiff.limit_points == []
    assert np.all(np.diff([row["P"] for row in stiff.rows]) > 0)
    assert [lp.kind for lp in fold(material="gent", Jm=100.0, v_max=6.0).limit_points] == ["max", "min"]
