"""The air-filled crater's suction cycle (ch. 7), in the range without wall-plate contact."""

import csv
import json
import math

from mpi4py import MPI

import pytest
from helpers import bcfem, refused

from bcfem.physics.cavitation import BISECTIONS
from bcfem.scenes import crater
from bcfem.theory.crater import eshelby_air, eshelby_liquid

LARGE = dict(specimen_radius=63.5, specimen_height=127.0,
             surface_energy=0.0)  # ~ the infinite body of Eshelby, no surface energy


@pytest.mark.slow
def test_small_preload_approaches_eshelby():
    deviations = []
    for eps in (0.01, 0.003):
        _, summary = crater.solve(crater.Params(preload=eps, **LARGE), MPI.COMM_WORLD)
        deviations.append(abs(summary["F_tilde"] / eshelby_air(eps, crater.Params().beta) - 1))
        # Boyle's law holds to solver tolerance at the end of stage 2
        assert abs(summary["fluid_law_residual"]) < 1e-10
    assert deviations[1] < deviations[0] < 0.015
    assert deviations[1] < 0.005


@pytest.mark.parametrize("fluid", ["air", "liquid"])
def test_zero_preload_is_a_cycle_with_zero_force(fluid):
    """The sweep of Fig. 7.6 starts at eps = 0: nothing to unload, F = 0, the fluid at p_a."""
    rows, summary = crater.solve(crater.Params(fluid=fluid, preload=0.0, size_crater=0.12), MPI.COMM_WORLD)
    assert summary["F_tilde"] == 0.0 and summary["eps_at_zero_force"] == 0.0
    assert summary["p2_over_pa"] == pytest.approx(1.0, abs=1e-12)
    assert summary["V2_over_V0"] == pytest.approx(1.0, abs=1e-6)  # the volume at rest, to the geometry's quadrature
    assert [r["stage"] for r in rows] == ["load", "unload"]


@pytest.mark.slow
def test_small_preload_keeps_symmetry():
    """--waves: at a preload below the creasing range no Fourier mode n = 1..6 loses stability
    on either stage. (A sideways n = 1 mode whose axis condition a + b = 0 was left to the
    energy made the suction's volume term at the crater's pole look unstable here.)"""
    _, summary = crater.solve(crater.Params(preload=0.2, size_crater=0.12, strain_step=0.05, waves=6),
                              MPI.COMM_WORLD)
    assert summary["symmetry_breaking"] == {} and summary["stability"] == "stable"
    assert not [e for e in summary["instabilities"] if e["kind"] == "waves"]
    assert summary["final_unstable_modes"] == 0


@pytest.mark.slow
def test_a_cycle_that_ends_on_a_saddle_says_so():
    """Past the creasing range Newton can follow unstable equilibria: hemisphere, eps = 0.4,
    gamma/(mu a) = 0.005, the zero-force state has one unstable axisymmetric mode, and the
    summary must say so rather than pass F~ off as a stable state's."""
    _, summary = crater.solve(crater.Params(preload=0.4, surface_energy=0.005), MPI.COMM_WORLD)
    last = [e for e in summary["instabilities"] if e["kind"] == "stability"][-1]
    assert summary["final_unstable_modes"] == last["unstable"] == 1
    assert last["stage"] == "unload"


@pytest.mark.slow
def test_liquid_small_preload_approaches_eshelby():
    """Incompressible liquid (ch. 8): V2 = V1, and Eshelby's Delta V1 = Delta V2 gives
    Delta p = -eps mu, so F~ = beta eps (eq. 8.6) as eps -> 0."""
    beta = crater.Params().beta
    deviations = []
    for eps in (0.01, 0.003):
        _, summary = crater.solve(crater.Params(fluid="liquid", preload=eps, **LARGE), MPI.COMM_WORLD)
        assert abs(summary["fluid_law_residual"]) < 1e-10  # the volume constraint holds
        deviations.append(abs(summary["F_tilde"] / eshelby_liquid(eps, beta) - 1))
    assert deviations[1] < deviations[0] < 0.015
    assert deviations[1] < 0.005


@pytest.mark.slow
@pytest.mark.parametrize("variant", [[], ["--fluid", "liquid", "--layer-thickness", "0.05", "--layer-stiffness", "10"],
                                     ["--bottom", "contact", "--retract", "0.05"]],
                         ids=["air", "liquid-layer", "bottom-contact"])
def test_cycle_outputs_and_mpi(tmp_path, variant):
    args = ["run", "crater", "--preload", "0.08", "--strain-step", "0.02", "--waves", "3", "--quiet", *variant]
    summaries = []
    for ranks in (1, 2):
        out = tmp_path / f"n{ranks}"
        res = bcfem(*args, "--out", out, ranks=ranks)
        assert res.returncode == 0, res.stderr
        summaries.append(json.loads((out / "summary.json").read_text()))
        header = (out / "branch.csv").read_text().splitlines()[0].split(",")
        assert header == ["stage", "eps", "V_over_V0", "p_over_pa", "A_over_A0", "F_tilde", "F_hat", "platen_force"]
        assert (out / "cycle.png").stat().st_size > 10_000
    serial, parallel = summaries
    assert parallel["ranks"] == 2
    for key in ("F_tilde", "V1_over_V0", "V2_over_V0", "p2_over_pa", "A2_over_A0"):
        assert parallel[key] == pytest.approx(serial[key], rel=1e-8)
    assert parallel["instabilities"] == serial["instabilities"] and serial["symmetry_breaking"] == {}
    if "--retract" in variant:
        assert serial["pull_off"]["kind"] == parallel["pull_off"]["kind"] == "the seal opens"
        assert parallel["pull_off"]["platen_force"] == pytest.approx(serial["pull_off"]["platen_force"], rel=1e-8)
    # suction: the air pressure dropped and the crater sprang back only partly
    assert serial["p2_over_pa"] < 1
    if "liquid" not in variant:  # air: the crater sprang back only partly, and little air leaks
        assert serial["V1_over_V0"] < serial["V2_over_V0"] < 1
        assert 0 < serial["gas_permeation"]["J_over_V0"] < 0.05
    else:  # liquid: the volume is held
        assert serial["V2_over_V0"] == pytest.approx(serial["V1_over_V0"], rel=1e-10)


@pytest.mark.parametrize("args, word", [
    (["--alpha", "1.2"], "alpha"),
    (["--alpha", "0"], "alpha"),
    (["--preload", "-0.1"], "preload"),
    (["--crater-radius", "12.7"], "--crater-radius"),
    (["--preload", "0.95"], "preload"),
    (["--beta", "0"], "beta"),
    (["--layer-thickness", "0.5"], "layer-thickness"),
    (["--layer-thickness", "-0.1"], "layer-thickness"),
    (["--layer-stiffness", "0"], "layer-stiffness"),
    (["--preload", "open"], "preload"),
    (["--strain-step", "0"], "strain-step"),
    (["--surface-energy", "0.5"], "surface-energy"),
    (["--self-contact", "5"], "self-contact"),
    (["--waves", "-1"], "waves"),
    (["--waves", "401"], "waves"),
    (["--max-snaps", "-1"], "max-snaps"),
    (["--max-snaps", "1001"], "max-snaps"),
    (["--max-snaps", "2.5"], "max-snaps"),
    (["--path", "relaxed"], "path"),
])
def test_bad_crater_input_exits_2_before_meshing(tmp_path, args, word):
    assert word in refused("run", "crater", *args, out=tmp_path / "bad")


@pytest.mark.slow
def test_no_locking_at_kappa_over_mu_1e6():
    """Taylor-Hood u-p: kappa/mu = 1e6 converges and differs from 1e3 and 1e4 runs by the
    compressibility itself, O(mu/kappa): ten times less from 1e4 than from 1e3."""
    runs = {k: crater.solve(crater.Params(preload=0.1, kappa_ratio=k), MPI.COMM_WORLD)[1]
            for k in (1e3, 1e4, 1e6)}
    for key in ("F_tilde", "V1_over_V0", "V2_over_V0"):
        far = abs(runs[1e3][key] / runs[1e6][key] - 1)
        near = abs(runs[1e4][key] / runs[1e6][key] - 1)
        assert far < 3e-3, (key, far)
        assert near < 0.2 * far + 1e-6, (key, near, far)


@pytest.mark.slow
@pytest.mark.convergence
def test_mesh_convergence_at_preload_0_3():
    """The smooth functionals of the cycle (V1, V2, p2) converge with the mesh at eps = 0.3;
    F~ = (1 - p2) A2/A0 also carries the rim position, which is known to a node spacing."""
    sizes = (0.12, 0.08, 0.06)
    runs = [crater.solve(crater.Params(preload=0.3, size_crater=h), MPI.COMM_WORLD)[1] for h in sizes]
    for key in ("V1_over_V0", "V2_over_V0", "p2_over_pa"):
        values = [r[key] for r in runs]
        assert abs(values[2] - values[1]) < 0.01 * abs(values[2]), (key, values)
    F = [r["F_tilde"] for r in runs]
    assert abs(F[2] / F[1] - 1) < 0.08, F


@pytest.mark.slow
@pytest.mark.mpi
def test_wall_surface_energy_shrinks_the_crater_as_an_exact_spherical_cavity():
    """The wall's surface energy gamma pulls the crater in with the Laplace pressure 2 gamma / R.
    The plate is a mirror plane for the frictionless bottom face, so the hemisphere is a spherical
    cavity in an (almost) infinite incompressible neo-Hookean solid, whose exact radial expansion
    under a cavity pressure p is p / mu = 5/2 - 2/lam - 1/(2 lam^4), lam = R/a. With
    p = -2 gamma / (lam a): the crater's volume lam^3 V0 and its rim area lam^2 A0 (the vent is open
    and the preload is tiny: the gamma = 0 run's shift is subtracted). Measured: 6e-5 and 8e-5
    off, from the specimen's finite size (5e-4 at 10 a: the (a/R)^3 of a far field), also on
    2 ranks."""
    from scipy.optimize import brentq

    far = dict(specimen_radius=127.0, specimen_height=254.0, preload=1e-4)  # 20 a, 40 a
    bare = crater.solve(crater.Params(surface_energy=0.0, **far), MPI.COMM_WORLD)[1]
    for x in (0.01, 0.002):  # gamma / (mu a)
        lam = brentq(lambda lam: 2.5 - 2 / lam - 0.5 / lam**4 + 2 * x / lam, 0.9, 1.0)
        s = crater.solve(crater.Params(surface_energy=x, **far), MPI.COMM_WORLD)[1]
        dV = s["V1_over_V0"] - bare["V1_over_V0"]
        assert abs(dV / (lam**3 - 1) - 1) < 3e-4, (x, dV, lam**3 - 1)
        dA = s["A2_over_A0"] / bare["A2_over_A0"] - 1
        assert abs(dA / (lam**2 - 1) - 1) < 3e-4, (x, dA, lam**2 - 1)
        # the first-order (linear) Laplace shrink, 3 (lam - 1) = -3/2 gamma/(mu a), is off by O(x)
        assert abs(dV / (-1.5 * x) - 1) > abs(dV / (lam**3 - 1) - 1)


@pytest.mark.slow
def test_a_bottom_face_in_contact_lifts_at_the_rim_and_pulls_on_the_wetted_area():
    """--bottom contact (the dissertation's frictionless plate): the rim lifts off the plate and
    the gap under it joins the cavity, so the suction acts out to the sealed contact line. At
    zero platen force the plate's push on the specimen is the suction force itself, for either
    bottom; the pressure barely moves, the wetted area grows a little."""
    coarse = dict(preload=0.2, size_crater=0.12, strain_step=0.05)
    _, held = crater.solve(crater.Params(**coarse), MPI.COMM_WORLD)
    _, contact = crater.solve(crater.Params(bottom="contact", **coarse), MPI.COMM_WORLD)
    for summary in (held, contact):  # at eps = 0.2 the wall is off the plate: A2 is all the suction's
        assert summary["F_tilde"] > 0
        assert summary["plate_reaction_tilde"] == pytest.approx(summary["F_tilde"], rel=1e-8)
    assert contact["p2_over_pa"] == pytest.approx(held["p2_over_pa"], abs=1e-3)
    assert 1 < contact["A2_over_A0"] / held["A2_over_A0"] < 1.05
    assert abs(contact["fluid_law_residual"]) < 1e-10


@pytest.mark.slow
def test_retraction_pulls_the_specimen_off_where_the_seal_opens():
    """--retract: past zero force the platen pulls; the plate's push falls until the seal opens,
    and there the pull is the suction force itself (nothing else holds the specimen). The
    cycle up to zero force is the one without retraction, row for row."""
    coarse = dict(preload=0.2, size_crater=0.12, strain_step=0.05, bottom="contact")
    plain, summary = crater.solve(crater.Params(**coarse), MPI.COMM_WORLD)
    rows, retracted = crater.solve(crater.Params(retract=0.1, **coarse), MPI.COMM_WORLD)
    assert rows[:len(plain)] == plain
    assert retracted["F_tilde"] == summary["F_tilde"]
    pull = [r for r in rows if r["stage"] == "retract"]
    assert pull and all(b["platen_force"] > a["platen_force"] for a, b in zip(pull, pull[1:]))
    off = retracted["pull_off"]
    assert off["kind"] == "the seal opens" and -0.1 < off["eps"] < 0
    assert off["platen_force"] == pytest.approx(off["F_tilde"], rel=1e-2)  # the push left: O(the bisection)
    assert off["platen_force"] > summary["F_tilde"] > 0


@pytest.mark.slow
@pytest.mark.mpi
@pytest.mark.serial
def test_bottom_contact_and_retraction_on_two_ranks_equal_serial(tmp_path):
    flags = ["--bottom", "contact", "--preload", "0.1", "--retract", "0.05", "--size-crater", "0.16",
             "--strain-step", "0.05", "--quiet", "--no-plots"]
    summaries, branches = [], []
    for ranks in (1, 2):
        out = tmp_path / f"n{ranks}"
        res = bcfem("run", "crater", *flags, "--out", out, ranks=ranks)
        assert res.returncode == 0, res.stderr
        summaries.append(json.loads((out / "summary.json").read_text()))
        with open(out / "branch.csv") as f:
            branches.append(list(csv.DictReader(f)))
    (serial, parallel), (rows, rows_2) = summaries, branches
    assert parallel["ranks"] == 2
    for key in ("F_tilde", "p2_over_pa", "A2_over_A0", "plate_reaction_tilde"):
        assert parallel[key] == pytest.approx(serial[key], rel=1e-7)
    assert (parallel["pull_off"] is None) == (serial["pull_off"] is None)
    if serial["pull_off"]:
        assert parallel["pull_off"]["eps"] == pytest.approx(serial["pull_off"]["eps"], abs=1e-8)
    assert len(rows) == len(rows_2)
    for a, b in zip(rows, rows_2):
        assert (a["stage"], float(a["eps"])) == (b["stage"], pytest.approx(float(b["eps"]), abs=1e-10))
        assert float(a["platen_force"]) == pytest.approx(float(b["platen_force"]), rel=1e-6, abs=1e-10)


def test_retraction_needs_a_bottom_that_can_lift(tmp_path):
    assert "--bottom contact" in refused("run", "crater", "--retract", "0.05", out=tmp_path / "r")


#: a liquid that cavitates early on a coarse mesh: unloading from 0.2, its pressure falls to
#: 0.9 p_a near eps = 0.1 (water's 0.023 p_a needs a preload of about 0.35)
CAVITATING = dict(fluid="liquid", preload=0.2, cavitation=0.9, size_crater=0.12, strain_step=0.025)


def test_a_cavitated_liquid_holds_its_vapour_pressure():
    p_v = CAVITATING["cavitation"]
    rows, summary = crater.solve(crater.Params(**CAVITATING), MPI.COMM_WORLD)
    event = summary["cavitation"]
    assert summary["phase_changes"] == [event] and event["kind"] == "cavitation" and event["stage"] == "unload"
    assert event["bracket"] <= CAVITATING["strain_step"] * 2.0**-BISECTIONS
    assert p_v - 0.01 < event["p_over_pa"] < p_v  # located where the liquid's pressure crosses p_v
    unload = [r for r in rows if r["stage"] == "unload"]
    liquid = [r for r in unload if r["eps"] > event["eps"]]
    vapour = [r for r in unload if r["eps"] <= event["eps"]]
    assert liquid and vapour and unload == liquid + vapour
    V1 = summary["V1_over_V0"]
    for r in liquid:  # the liquid holds its volume, above the vapour pressure
        assert r["p_over_pa"] > p_v and r["V_over_V0"] == pytest.approx(V1, rel=1e-9)
    for r in vapour:  # cavitated: p_v held, the volume free and above the liquid's
        assert r["p_over_pa"] == pytest.approx(p_v, abs=1e-15) and r["V_over_V0"] > V1
    assert summary["p2_over_pa"] == pytest.approx(p_v, abs=1e-15) and summary["fluid_law_residual"] == 0.0
    assert summary["F_tilde"] == pytest.approx((1 - p_v) * summary["A2_over_A0"], rel=1e-12)


@pytest.mark.slow
def test_without_cavitation_the_liquid_cycle_is_unchanged():
    """The default (-inf) leaves the check out; a vapour pressure the liquid never reaches
    (-1e3 p_a, where the preload 0.4 takes it to -0.3 p_a past a snap) checks every step and
    changes nothing: the same rows as the default to round-off."""
    base = dict(fluid="liquid", preload=0.4)
    default, summary = crater.solve(crater.Params(**base), MPI.COMM_WORLD)
    assert summary["p2_over_pa"] < 0 and summary["cavitation"] is None
    for cavitation in (-math.inf, -1e3):
        rows, summary = crater.solve(crater.Params(**base, cavitation=cavitation), MPI.COMM_WORLD)
        assert summary["phase_changes"] == [] and len(rows) == len(default)
        for row, expected in zip(rows, default):
            assert row.keys() == expected.keys()
            for key, value in row.items():
                if isinstance(value, float):
                    assert value == pytest.approx(expected[key], rel=1e-12, abs=1e-14), (row, key)
                else:
                    assert value == expected[key]


@pytest.mark.slow
@pytest.mark.serial
def test_cavitation_on_two_ranks_equals_serial(tmp_path):
    flags = [x for k, v in CAVITATING.items() for x in (f"--{k.replace('_', '-')}", str(v))]
    summaries, branches = [], []
    for ranks in (1, 2):
        out = tmp_path / f"n{ranks}"
        res = bcfem("run", "crater", *flags, "--quiet", "--no-plots", "--out", out, ranks=ranks)
        assert res.returncode == 0, res.stderr
        summaries.append(json.loads((out / "summary.json").read_text()))
        with open(out / "branch.csv") as f:
            branches.append(list(csv.DictReader(f)))
    (serial, parallel), (rows, rows_2) = summaries, branches
    assert parallel["ranks"] == 2 and serial["cavitation"] is not None
    assert parallel["cavitation"]["eps"] == pytest.approx(serial["cavitation"]["eps"], abs=1e-12)
    for key in ("F_tilde", "V2_over_V0", "p2_over_pa", "A2_over_A0", "eps_at_zero_force"):
        assert parallel[key] == pytest.approx(serial[key], rel=1e-8)
    assert len(rows) == len(rows_2)
    for a, b in zip(rows, rows_2):  # the zero force's eps is a root: equal to its round-off
        assert float(a["eps"]) == pytest.approx(float(b["eps"]), abs=1e-10)
        assert float(a["p_over_pa"]) == pytest.approx(float(b["p_over_pa"]), rel=1e-8)


@pytest.mark.parametrize("args, word", [
    (["--cavitation", "1"], "cavitation"),
    (["--cavitation", "-2000"], "cavitation"),
    (["--cavitation", "nan"], "cavitation"),
    (["--cavitation", "water"], "cavitation"),
    (["--fluid", "liquid", "--cavitation", "0.023", "--path", "fundamental"], "--cavitation"),
    (["--fluid", "liquid", "--cavitation", "0.023", "--bottom", "contact", "--retract", "0.05"], "--cavitation"),
])
def test_bad_cavitation_exits_2_before_meshing(tmp_path, args, word):
    assert word in refused("run", "crater", *args, out=tmp_path / "bad")


def test_a_liquid_crater_closed_on_loading_cavitates_as_air_leaves_a_vacuum():
    """Closed on loading, no liquid holds the wall: it cavitates at the seal. At p_v = 0 the
    vapour is the air crater's vacuum, row for row; without cavitation F = 0 (eq. 8.8)."""
    closed = dict(preload=0.45, size_crater=0.12, strain_step=0.05)
    air, air_summary = crater.solve(crater.Params(**closed), MPI.COMM_WORLD)
    rows, summary = crater.solve(crater.Params(fluid="liquid", cavitation=0.0, **closed), MPI.COMM_WORLD)
    assert summary["cavitation"]["eps"] == 0.45 and "cavitates" in summary["closure_note"]
    assert rows == air and summary["F_tilde"] == air_summary["F_tilde"] > 0.5
    _, held = crater.solve(crater.Params(fluid="liquid", **closed), MPI.COMM_WORLD)
    assert held["F_tilde"] == 0.0 and held["cavitation"] is None
