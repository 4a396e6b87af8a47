"""The air-filled crater's suction cycle (ch. 7), in the range without wall-plate contact."""

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import pytest
from mpi4py import MPI

from bcfem.scenes import crater

BIN = Path(sys.executable).parent
LARGE = dict(specimen_radius=63.5, specimen_height=127.0, load_steps=3,
             surface_energy=0.0)  # ~ the infinite body of Eshelby, no surface energy


def eshelby(eps, beta, nu=0.5):
    """Eq. 7.12 (re-derived: Eshelby's Delta V1 = -3/2 (1-nu) eps V0, Delta V2 = 3/4 dp/mu V0,
    and Boyle's law give F/(p_a A0) as the small root of a quadratic; no typo found)."""
    K = 4 * beta / 3
    return 0.5 * ((1 + K) - math.sqrt((1 + K) ** 2 - 8 * (1 - nu) * beta * eps))


def test_small_preload_approaches_eshelby():
    deviations = []
    for eps in (0.01, 0.003):
        _, summary = crater.solve(crater.Params(preload=eps, **LARGE), MPI.COMM_WORLD)
        deviations.append(abs(summary["F_tilde"] / eshelby(eps, crater.Params().beta) - 1))
        # Boyle's law holds to solver tolerance at the end of stage 2
        assert abs(summary["gas_law_residual"]) < 1e-10
    assert deviations[1] < deviations[0] < 0.015
    assert deviations[1] < 0.005


def test_cycle_outputs_and_mpi(tmp_path):
    args = ["run", "crater", "--preload", "0.08", "--load-steps", "4", "--quiet"]
    env = {**os.environ, "PATH": f"{BIN}:{os.environ['PATH']}"}
    summaries = []
    for ranks in (1, 2):
        out = tmp_path / f"n{ranks}"
        cmd = [str(BIN / "bcfem"), *args, "--out", str(out)]
        if ranks > 1:
            cmd = [str(BIN / "mpirun"), "-n", str(ranks), *cmd]
        res = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=600)
        assert res.returncode == 0, res.stderr
        summaries.append(json.loads((out / "summary.json").read_text()))
        header = (out / "branch.csv").read_text().splitlines()[0].split(",")
        assert header == ["stage", "eps", "V_over_V0", "p_over_pa", "A_over_A0", "F_tilde"]
        assert (out / "cycle.png").stat().st_size > 10_000
    serial, parallel = summaries
    assert parallel["ranks"] == 2
    for key in ("F_tilde", "V1_over_V0", "V2_over_V0", "p2_over_pa", "A2_over_A0"):
        assert parallel[key] == pytest.approx(serial[key], rel=1e-8)
    # suction: the air pressure dropped and the crater sprang back only partly
    assert serial["p2_over_pa"] < 1 and serial["V1_over_V0"] < serial["V2_over_V0"] < 1
    assert 0 < serial["gas_permeation"]["J_over_V0"] < 0.05


@pytest.mark.parametrize("args, word", [
    (["--alpha", "1.2"], "alpha"),
    (["--crater-radius", "12.7"], "crater radius"),
    (["--preload", "0.95"], "preload"),
    (["--beta", "0"], "beta"),
])
def test_bad_crater_input_exits_2_before_meshing(tmp_path, args, word):
    out = tmp_path / "bad"
    res = subprocess.run([str(BIN / "bcfem"), "run", "crater", *args, "--out", str(out)],
                         capture_output=True, text=True, timeout=120)
    assert res.returncode == 2 and word in res.stderr and not out.exists()
