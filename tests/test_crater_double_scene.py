"""The scene ``crater-double``: the chambers as state along a cycle.

A coarse cell of a confined array (outer face on rollers, radius 2 r0, height 2 H), where the
sidewall reaches the protuberance at eps ~ 0.012:

* one cavity before the split obeys Boyle's law; the split is located to the bisection's
  bracket; after it, each chamber keeps its own gas (p_i V_i = const) and the two pressures
  part; at the merge on unloading the gas is pooled, its total conserved;
* bonded contact keeps the chambers apart down to eps = 0;
* a liquid sealed at the preload keeps each chamber's volume (no cavitation), or cavitates
  at its vapour pressure and holds it;
* ``mpirun -n 2`` gives the serial cycle (marker ``mpi``);
* (bonded, liquid and two ranks are marked ``slow``: ``make test-all``);
* bad input exits 2 before meshing.
"""

import functools
import math

from mpi4py import MPI

import pytest
from helpers import refused, same_loads

from bcfem.scenes import crater, crater_double
from bcfem.scenes.crater.model import Crater
from bcfem.scenes.crater_double.model import DoubleCrater
from bcfem.scenes.crater_double.stages import BISECTIONS

CELL = dict(cell="array", specimen_radius=2.0, specimen_height=2.0, size_wall=0.16, size_contact=0.04,
            preload=0.0125, strain_step=0.005)
#: no protuberance: a plain cylindrical crater, vented while loading, on a frictionless plate
PLAIN = dict(protuberance_radius=0.0, seal="preload", plate="frictionless", size_wall=0.16, size_contact=0.04,
             specimen_radius=3.0, specimen_height=3.0, preload=0.05, strain_step=0.0125)


@functools.cache
def cycle(comm=MPI.COMM_SELF, **changes):
    return crater_double.solve(crater_double.Params(**{**CELL, **changes}), comm)


def test_split_and_merge_conserve_each_chambers_gas():
    rows, summary = cycle()
    split, merge = summary["split"], summary["merge"]
    print("split:", split, "\nmerge:", merge)
    # located to the bisection's bracket: a step of at most strain_step / 2 halved BISECTIONS times
    assert 0.01 < split["eps"] < CELL["preload"] and split["bracket"] <= CELL["strain_step"] * 2.0**-BISECTIONS
    assert merge is not None and merge["bracket"] <= CELL["strain_step"] * 2.0**-BISECTIONS
    one = [r for r in rows if r["chambers"] == 1]
    two = [r for r in rows if r["chambers"] == 2]
    assert len(two) >= 2 and {r["stage"] for r in two} == {"load"}
    # p V = n in every chamber at every state, to solver tolerance
    assert max(r["fluid_law_residual"] or 0.0 for r in rows) < 1e-8
    rest = rows[0]  # settled on the plate at p_a (the walls' surface energy shrinks it a little)
    assert rest["eps"] == 0.0 and rest["p_c1_over_pa"] == 1.0 and 0.99 < rest["V_c1"] < 1
    for r in one:  # one cavity sealed there: p V = V_rest
        assert r["p_c1_over_pa"] * r["V_c1"] == pytest.approx(rest["V_c1"], rel=1e-8)
    at_split = two[0]
    assert at_split["p_c1_over_pa"] == at_split["p_c2_over_pa"]
    assert at_split["V_c1"] + at_split["V_c2"] == pytest.approx(rest["V_c1"] / at_split["p_c1_over_pa"], rel=1e-8)
    amounts = (at_split["p_c1_over_pa"] * at_split["V_c1"], at_split["p_c2_over_pa"] * at_split["V_c2"])
    for r in two:
        assert (r["p_c1_over_pa"] * r["V_c1"], r["p_c2_over_pa"] * r["V_c2"]) == pytest.approx(amounts, rel=1e-8)
    # sealed apart, the pressures part: by far more than the solver's tolerance
    assert abs(two[-1]["p_c1_over_pa"] - two[-1]["p_c2_over_pa"]) > 1e-5
    # the merge pools the gas: its total is that of the two chambers
    after = next(r for r in rows if r["stage"] == "unload" and r["chambers"] == 1)
    pooled = merge["p_c1_over_pa"] * merge["V_c1"] + merge["p_c2_over_pa"] * merge["V_c2"]
    assert after["p_c1_over_pa"] * after["V_c1"] == pytest.approx(pooled, rel=1e-8)
    assert pooled == pytest.approx(rest["V_c1"], rel=1e-8)  # and the one cavity's, sealed at rest
    assert rows[-1]["eps"] == 0.0 and summary["F_tilde"] == rows[-1]["F_tilde"]


@pytest.mark.slow
def test_bonded_contact_keeps_the_chambers_apart():
    rows, summary = cycle(contact="bonded")
    assert summary["merge"] is None and rows[-1]["eps"] == 0.0 and rows[-1]["chambers"] == 2
    assert summary["split"]["bonded_pairs"] >= 1
    assert max(r["fluid_law_residual"] or 0.0 for r in rows) < 1e-8
    # unloaded with the contact held, the chambers end at pressures of their own
    assert abs(summary["p_c1_over_pa"] - summary["p_c2_over_pa"]) > 1e-3
    assert summary["F_tilde_per_chamber"] == {"C1": summary["F_tilde"], "C2": 0.0}


@pytest.mark.slow
def test_a_liquid_keeps_each_chambers_volume():
    rows, summary = cycle(fluid="liquid", seal="preload", cavitation=-math.inf)
    sealed = [r for r in rows if r["stage"] == "unload"]
    assert summary["split"] is not None and all(r["chambers"] == 2 for r in sealed)
    for key in ("V_c1", "V_c2"):
        assert max(r[key] for r in sealed) - min(r[key] for r in sealed) < 1e-8
    # vented while loading: both chambers at p_a until sealed
    assert all(r["p_c1_over_pa"] == r["p_c2_over_pa"] == 1.0 for r in rows if r["stage"] == "load")
    assert summary["p_c1_over_pa"] < -10  # no cavitation: the liquid takes any tension


@pytest.mark.slow
def test_a_liquid_cavitates_at_its_vapour_pressure_and_holds_it():
    p_v = crater_double.Params.cavitation
    rows, summary = cycle(fluid="liquid", seal="preload")
    event = summary["cavitation"]
    assert event["stage"] == "unload" and event["bracket"] <= CELL["strain_step"] * 2.0**-BISECTIONS
    # located where the liquid's pressure crosses p_v (within the bracket's pressure change)
    p_event = event[f"p_{event['chamber'].lower()}_over_pa"]
    assert p_v - 0.01 < p_event < p_v
    at_seal = next(r for r in rows if r["stage"] == "unload")
    vapour = [r for r in rows if r["vapour"]]
    assert vapour and all(r["fluid_law_residual"] < 1e-8 for r in vapour)
    for r in vapour:  # a cavitated chamber holds p_v, and its volume is at least the liquid's
        chambers = ("c1", "c2") if r["chambers"] == 2 else ("c1",)
        assert min(r[f"p_{c}_over_pa"] for c in chambers) >= p_v - 1e-12
        assert r["V_c1"] + r["V_c2"] >= at_seal["V_c1"] + at_seal["V_c2"] - 1e-8
    # unloaded: the vapour pulls on the plate with (1 - p_v) over the wetted area
    assert summary["F_tilde"] == pytest.approx((1 - p_v) * rows[-1]["A_c1_over_A0"], rel=1e-12)


@pytest.mark.slow
def test_the_wave_check_watches_without_changing_the_path():
    """--waves scans the n-wave modes after every step: the path is the same, the check's
    time is spent, and the cell keeps its symmetry (no n-wave mode is unstable)."""
    rows, summary = cycle(waves=2)
    reference, unchecked = cycle()
    assert [r["chambers"] for r in rows] == [r["chambers"] for r in reference]
    for key in ("eps", "p_c1_over_pa", "p_c2_over_pa", "V_c1", "V_c2"):
        assert [r[key] for r in rows] == pytest.approx([r[key] for r in reference], rel=1e-12)
    assert unchecked["symmetry_breaking"] is None and summary["symmetry_breaking"] == {}
    assert summary["time_split_s"]["stability"] > 2 * unchecked["time_split_s"]["stability"]


@pytest.mark.mpi
@pytest.mark.slow
@pytest.mark.parametrize("case", ["air", "cavitation", "plain"])
def test_two_ranks_equal_serial(case):
    """The split and merge of air, water's cavitation in the array cell, and the plain
    cylinder (no protuberance) give the serial cycle on 2 ranks."""
    if MPI.COMM_WORLD.size == 1:
        pytest.skip("needs mpirun -n 2")
    params = {"air": CELL, "cavitation": {**CELL, "fluid": "liquid", "seal": "preload"}, "plain": PLAIN}[case]
    rows, summary = crater_double.solve(crater_double.Params(**params), MPI.COMM_WORLD)
    reference, reference_summary = crater_double.solve(crater_double.Params(**params), MPI.COMM_SELF)
    for event in ("split", "merge", "cavitation"):  # located to the bisection's bracket
        mine, theirs = summary[event], reference_summary[event]
        assert (mine is None) == (theirs is None), event
        if mine is not None:
            assert abs(mine["eps"] - theirs["eps"]) <= max(mine["bracket"], theirs["bracket"]), event
    if case == "cavitation":
        assert summary["cavitation"] is not None and summary["p_c1_over_pa"] == pytest.approx(0.023, abs=1e-12)
    # the states at the same strain: every checkpoint, and the events' where the bisections agree
    # (a cut step, or a bisection's side, may differ where round-off decides a Newton solve)
    pairs = same_loads(rows, reference, "eps")
    step, preload = params["strain_step"], params["preload"]
    declared = {(r["stage"], r["eps"]) for r in reference if r["eps"] == preload or round(r["eps"] / step, 9) % 1 == 0}
    assert declared <= {(ref["stage"], ref["eps"]) for _, ref in pairs}
    for r, ref in pairs:
        assert r["chambers"] == ref["chambers"]
        for key in ("p_c1_over_pa", "p_c2_over_pa", "V_c1", "V_c2", "F_tilde"):
            assert r[key] == pytest.approx(ref[key], rel=1e-8, abs=1e-10), key


@functools.cache
def plain_crater(comm=MPI.COMM_SELF):
    """The scene ``crater`` on the plain cylindrical crater of ``crater-double`` (R0 = 0): the
    same mesh, material, walls and vented loading, sealed at the preload."""
    double = crater_double.Params(**{**PLAIN, "preload": crater_double.Params.preload})
    geometry = double.geometry()

    class CylinderParams(crater.Params):
        def geometry(self):
            return geometry

    class CylinderCrater(Crater):
        walls = DoubleCrater.walls
        create_mesh = staticmethod(DoubleCrater.create_mesh)

    params = CylinderParams(crater_radius=geometry.r0, specimen_radius=geometry.specimen_radius,
                            specimen_height=geometry.specimen_height, beta=double.beta,
                            preload=PLAIN["preload"], strain_step=PLAIN["strain_step"],
                            surface_energy=double.surface_energy, size_crater=0.5)
    return crater.solve(params, comm, CylinderCrater)


def test_without_a_protuberance_it_is_the_crater_scene():
    """R0 = 0: one chamber that never splits; every state the crater scene also reaches
    (vented loading, sealed at the preload, unloading) agrees to solver tolerance."""
    rows, summary = crater_double.solve(crater_double.Params(**PLAIN), MPI.COMM_SELF)
    reference, _ = plain_crater()
    assert summary["split"] is None and summary["least_sidewall_gap"] is None
    assert all(r["chambers"] == 1 for r in rows)
    same = {(r["stage"], round(r["eps"], 12)): r for r in reference}
    common = [(r, same[(r["stage"], round(r["eps"], 12))]) for r in rows
              if (r["stage"], round(r["eps"], 12)) in same and r["eps"] > 0]
    assert {r["stage"] for r, _ in common} == {"load", "unload"} and len(common) >= 6
    for r, c in common:
        assert r["V_c1"] == pytest.approx(c["V_over_V0"], rel=1e-8)
        assert r["p_c1_over_pa"] == pytest.approx(c["p_over_pa"], rel=1e-8)
        assert r["A_c1_over_A0"] == pytest.approx(c["A_over_A0"], rel=1e-8)
        assert r["F_tilde"] == pytest.approx(c["F_tilde"], rel=1e-8, abs=1e-10)


@pytest.mark.parametrize("args, word", [(["--gap", "0"], "gap"), (["--protuberance-radius", "0.6"], "protuberance"),
                                        (["--preload", "0.95"], "preload"), (["--cell", "hex"], "cell"),
                                        (["--specimen-radius", "0.5"], "specimen-radius"),
                                        (["--protuberance-radius=-0.1"], "protuberance"),
                                        (["--cavitation", "1.5"], "cavitation"), (["--top", "glued"], "top")])
def test_bad_input_exits_2_naming_it(tmp_path, args, word):
    assert word in refused("run", "crater-double", *args, out=tmp_path)
