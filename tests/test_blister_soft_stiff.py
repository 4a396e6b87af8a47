"""Scene ``blister-soft`` at the stiff end of its range, stiffness ratio 1e6 (both edges).

At mu_s R0/(mu_f t0) = 1e6 the substrate is rigid to 1e-6: the bonded blister is
``blister-rigid``'s clamped one and the adhesive edge's onset is ``blister-rigid --edge
adhesive``'s. Fig. 3.14's interface energies (gamma_ls - dgamma = 2.5, onset past the pressure
maximum, the step where a long Newton path once landed on another equilibrium), traced to
V/V0 = 4 (slow).
"""

import json

import pytest
from helpers import bcfem

from bcfem.io import read_csv

STIFF = ("--stiffness-ratio", "1e6", "--alpha", "0.5", "--gamma-ls", "3.0", "--delta-gamma", "0.5", "--v-max", "4")


def run(tmp_path, name, *args):
    out = tmp_path / name
    result = bcfem("run", *args, "--out", out, "--no-plots")
    assert result.returncode == 0, result.stderr[-3000:]
    return json.loads((out / "summary.json").read_text()), read_csv(out / "branch.csv")


@pytest.mark.slow
@pytest.mark.serial
def test_ratio_1e6_is_the_rigid_substrate_on_both_edges(tmp_path):
    clamped, _ = run(tmp_path, "clamped", "blister-rigid", "--material", "neo-hookean", "--alpha", "0.5",
                     "--v-max", "4")
    adhesive, _ = run(tmp_path, "adhesive", "blister-rigid", "--material", "neo-hookean", "--alpha", "0.5",
                      "--edge", "adhesive", "--adhesion", "2.5", "--v-max", "4")
    (peak,) = clamped["limit_points"]
    for edge in ("bonded", "adhesive"):
        soft, rows = run(tmp_path, f"soft_{edge}", "blister-soft", "--edge", edge, *STIFF)
        assert rows[-1]["V_over_V0"] == pytest.approx(4.0, rel=1e-9)
        assert min(row["J_min"] for row in rows) > 0.99
        # the pressure maximum comes before the onset: the same on both edges, the rigid one's
        (limit,) = soft["limit_points"]
        assert limit["P"] == pytest.approx(peak["P"], rel=1e-4), edge
        assert limit["V_over_V0"] == pytest.approx(peak["V_over_V0"], abs=1e-3), edge
    onset = soft["delamination_onset"]
    rigid = adhesive["delamination_onset"]
    assert onset["V_over_V0"] == pytest.approx(rigid["V_over_V0"], abs=1e-3)
    assert onset["P"] == pytest.approx(rigid["P"], rel=1e-4)
