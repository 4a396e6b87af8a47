"""The crater design space (sections 7.3-7.4, ch. 8): reinforcement layers, the closure
preload eps_m, liquid at full closure, and the stability classification."""

import json

from mpi4py import MPI

import pytest
from helpers import bcfem

from bcfem.scenes import crater

slow = pytest.mark.slow


def cycle(**kwargs):
    return crater.solve(crater.Params(**kwargs), MPI.COMM_WORLD)[1]


@pytest.fixture(scope="module")
def closure_run():
    """The hemisphere pressed to closure: (rows, summary)."""
    return crater.solve(crater.Params(preload=crater.PRELOAD_TO_CLOSURE), MPI.COMM_WORLD)


@pytest.fixture(scope="module")
def hemisphere_to_closure(closure_run):
    return closure_run[1]


@slow
def test_layer_as_stiff_as_the_specimen_changes_nothing():
    """beta' = 1: the layer is a second region of the same material on another mesh; the
    cycle agrees with the unreinforced one to the discretisation error."""
    plain = cycle(preload=0.2)
    lined = cycle(preload=0.2, layer_thickness=0.1, layer_stiffness=1.0)
    for key in ("F_tilde", "V1_over_V0", "V2_over_V0", "p2_over_pa"):
        assert lined[key] == pytest.approx(plain[key], rel=1e-3), key


@slow
def test_stiff_thin_layer_converges_and_strengthens():
    """alpha' = 0.03, beta' = 30 (Fig. 7.11c's layer): the stiff lining springs back, so the
    crater keeps more of its volume and the suction rises (here about twice)."""
    plain = cycle(preload=0.2)
    lined = cycle(preload=0.2, layer_thickness=0.03, layer_stiffness=30.0)
    assert lined["V2_over_V0"] > plain["V2_over_V0"]
    assert lined["F_tilde"] > 1.5 * plain["F_tilde"]


@slow
def test_closure_preload_brackets_the_first_closed_state(closure_run):
    """eps_m closes the crater (V1 <= CLOSURE_VOLUME V0; stage 2 has a vacuum inside:
    F = p_a A2, eq. 7.17, and says so); every loaded state 0.01 below it is open. (The loading
    is the same whatever the preload, so the load rows stand for the cycles pressed less.)"""
    rows, summary = closure_run
    eps_m = summary["eps_m"]
    assert 0.3 < eps_m < 0.5
    assert summary["V1_over_V0"] <= crater.CLOSURE_CRITERIA.volume and summary["p2_over_pa"] == 0.0
    assert summary["F_tilde"] == pytest.approx(summary["A2_over_A0"], rel=1e-12)
    assert "eq. 7.17" in summary["closure_note"]
    below = [r for r in rows if r["stage"] == "load" and r["eps"] <= eps_m - 0.01]
    assert below and max(r["eps"] for r in below) > eps_m - 0.05
    assert min(r["V_over_V0"] for r in below) > crater.CLOSURE_CRITERIA.volume


@slow
def test_a_crater_still_open_at_the_closure_limit_is_a_result(monkeypatch):
    """``--preload closure`` that reaches MAX_CLOSURE_PRELOAD with the crater open reports
    so (eps_m None, a note) and cycles from there: the plain cycle at that preload."""
    from bcfem.scenes.crater import stages

    monkeypatch.setattr(stages, "MAX_CLOSURE_PRELOAD", 0.1)  # the hemisphere closes at ~0.4
    summary = cycle(preload=crater.PRELOAD_TO_CLOSURE)
    plain = cycle(preload=0.1)
    assert summary["eps_m"] is None and summary["preload"] == 0.1
    assert "does not close up to eps = 0.1" in summary["closure_note"]
    for key in ("F_tilde", "V1_over_V0", "V2_over_V0", "p2_over_pa"):
        assert summary[key] == pytest.approx(plain[key], rel=1e-9), key
    assert abs(summary["fluid_law_residual"]) < 1e-8


@slow
def test_sweep_is_rank_count_invariant(tmp_path):
    """`bcfem sweep crater` gives the same CSV on 1 and 2 ranks (each point is a serial
    cycle); the stability class is part of it. The alpha axis is given the issue's way,
    as a flag with start:stop:step."""
    grid = ["sweep", "crater", "--alpha", "0.5:1:0.5", "--grid", "layer_stiffness=1,10", "--layer-thickness",
            "0.05", "--preload", "0.05", "--size-crater", "0.12", "--quiet"]
    csv = {}
    for ranks in (1, 2):
        out = tmp_path / f"np{ranks}"
        res = bcfem(*grid, "--out", out, ranks=ranks)
        assert res.returncode == 0, res.stderr
        csv[ranks] = (out / "sweep.csv").read_text()
    assert csv[1] == csv[2]
    lines = csv[1].splitlines()
    assert len(lines) == 5 and "failed" not in csv[1] and "stability" in lines[0]


@slow
def test_stability_classification(hemisphere_to_closure):
    """A small preload is stable throughout; closing the hemisphere passes instabilities
    already on loading (the inertia of the tangent turns negative)."""
    plain = cycle(preload=0.1)
    assert plain["stability"] == "stable" and plain["closure_note"] is None
    assert hemisphere_to_closure["stability"] == "unstable-both"
    assert any(e["stage"] == "load" for e in hemisphere_to_closure["instabilities"])


def test_symmetry_classes_come_from_waves_beyond_the_axisymmetric_count():
    """``stability_waves`` counts only waves events with more unstable n-wave modes than
    axisymmetric ones (copies of an axisymmetric crease do not break symmetry)."""
    def waves(stage, eps, breaks):
        return {"stage": stage, "eps": eps, "kind": "waves", "unstable": 1, "waves": [1, 2],
                "breaks_symmetry": breaks}

    copies = [{"stage": "load", "eps": 0.35, "kind": "stability", "unstable": 1}, waves("load", 0.35, False)]
    assert crater.classify(copies) == "unstable-both"  # the axisymmetric class counts the crease
    assert crater.classify([e for e in copies if e.get("breaks_symmetry")]) == "stable"
    assert crater.symmetry_breaking(copies) == {}
    events = copies + [waves("unload", 0.3, True), waves("unload", 0.2, True)]
    assert crater.symmetry_breaking(events) == {"unload": {"eps": 0.3, "waves": [1, 2]}}
    assert crater.classify([e for e in events if e.get("breaks_symmetry")]) == "unstable-unloading"


@slow
def test_closed_liquid_crater_gives_no_suction(hemisphere_to_closure):
    """Eq. 8.8: a liquid crater closed on loading stays closed (V2 = V1 = 0): F_hat = 0, said
    so; the loading (vented) is the air crater's, so eps_m is the same."""
    summary = cycle(fluid="liquid", preload=crater.PRELOAD_TO_CLOSURE)
    assert summary["eps_m"] == pytest.approx(hemisphere_to_closure["eps_m"], rel=1e-10)
    assert summary["F_hat"] == 0.0 and summary["V2_over_V0"] <= crater.CLOSURE_CRITERIA.volume
    assert "eq. 8.8" in summary["closure_note"]


@slow
def test_a_soft_shallow_crater_stays_closed_and_says_so():
    """alpha = 0.25, beta = 0.5 (Fig. 7.10, top left): pressed flat, the crater's wall needs
    less than p_a to lift, so the vacuum holds it on the plate through the unloading. No
    cavity, no suction area: F~ ~ 0, and the note says why."""
    summary = cycle(preload=crater.PRELOAD_TO_CLOSURE, alpha=0.25, beta=0.5)
    assert summary["V2_over_V0"] <= crater.CLOSURE_CRITERIA.volume
    assert summary["F_tilde"] == pytest.approx(summary["A2_over_A0"], rel=1e-12) and summary["F_tilde"] < 1e-3
    assert "stays closed after unloading" in summary["closure_note"]
    # a stiffer one (beta = 10) springs open: a cavity, and no such note
    stiff = cycle(preload=crater.PRELOAD_TO_CLOSURE, alpha=0.25, beta=10.0)
    assert stiff["V2_over_V0"] > 0.1 and stiff["F_tilde"] > 0.9
    assert "stays closed" not in stiff["closure_note"]


@slow
def test_thin_stiff_lining_closes_with_a_trapped_pocket():
    """alpha' = 0.015, beta' = 30: the lining folds onto the plate and traps pockets, so V1
    never reaches CLOSURE_VOLUME V0. The crater counts as closed once the wall lies on the
    plate up to the axis with at most TRAPPED_VOLUME V0 left; stage 2 has a vacuum inside,
    and the neglected remnant is reported."""
    summary = cycle(preload=crater.PRELOAD_TO_CLOSURE, alpha=1.0, beta=1.0, layer_thickness=0.015, layer_stiffness=30.0)
    assert crater.CLOSURE_CRITERIA.volume < summary["V1_over_V0"] <= crater.CLOSURE_CRITERIA.trapped
    assert 0.3 < summary["eps_m"] < 0.6
    assert summary["p2_over_pa"] == 0.0 and summary["F_tilde"] == pytest.approx(summary["A2_over_A0"], rel=1e-12)
    assert "trapped remnant" in summary["closure_note"]


@slow
def test_a_lining_folding_on_the_plate_passes_where_newton_cycled():
    """alpha' = 0.06, beta' = 3 (a Fig. 7.11b point): at eps = 0.2728 the wall folds on the
    plate, and a node at the fold's tip lies behind a wall segment, where its mean normal
    turns edge-on. Regression: facing is decided once per solve (self_contact.py), so the
    pair does not switch between iterates, the cycle completes, and the trapped air obeys
    Boyle's law."""
    summary = cycle(preload=0.28, alpha=1.0, beta=1.0, layer_thickness=0.06, layer_stiffness=3.0)
    assert summary["preload"] == 0.28 and summary["V1_over_V0"] > 0.1
    assert abs(summary["fluid_law_residual"]) < 1e-8
    assert 0 < summary["p2_over_pa"] < 1 and 0 < summary["F_tilde"] < 1


@slow
def test_stiffness_contrasts_of_1e3_and_1e4_converge_to_a_rigid_lining():
    """beta' = 1e3 and 1e4 (alpha' = 0.03) converge, and the lining tends to a rigid shell:
    the crater's volume change on loading falls as 1/beta' (a thin shell's compliance;
    measured 3.53e-3 and 3.32e-4 at eps = 0.2), and so does the suction."""
    runs = [cycle(preload=0.2, layer_thickness=0.03, layer_stiffness=s) for s in (1e3, 1e4)]
    change = [1 - r["V1_over_V0"] for r in runs]
    assert 8 < change[0] / change[1] < 12.5, change
    assert 8 < runs[0]["F_tilde"] / runs[1]["F_tilde"] < 12.5, [r["F_tilde"] for r in runs]
    for r in runs:
        assert abs(r["fluid_law_residual"]) < 1e-8 and r["stability"] == "stable", r


def test_a_failed_cycle_is_traced_again_with_bounded_steps(monkeypatch):
    """The control flow of the retrace (the real failures it saves take minutes each): a
    cycle that gets through is traced once, with full Newton steps; one that fails is traced
    again, carefully, and says why; a second failure names both, and the run says failed."""
    from bcfem.path.stepping import SteppingError
    from bcfem.run.runner import SolveError
    from bcfem.run.stages import StagedScene

    calls = []

    def stages(self, run):  # both stages, as the crater's cycle calls them
        calls.append(self.careful)
        run.record({"eps": 0.0})
        if self.careful in fail:
            raise SteppingError(f"{'careful' if self.careful else 'first'} failed", 0.5)
        run.results.update(F_tilde=1.0, retraced=None)

    monkeypatch.setattr(StagedScene, "solve", stages)
    params = crater.Params()
    fail = ()
    rows, summary = crater.solve(params, MPI.COMM_SELF)
    assert rows == [{"eps": 0.0}] and summary["F_tilde"] == 1.0 and summary["retraced"] is None
    assert summary["status"] == "ok" and calls == [False]
    calls.clear()
    fail = (False,)
    rows, summary = crater.solve(params, MPI.COMM_SELF)
    assert calls == [False, True] and summary["retraced"] == "first failed" and len(rows) == 1
    calls.clear()
    fail = (False, True)
    with pytest.raises(SolveError, match="careful failed .*the first trace: first failed") as failure:
        crater.solve(params, MPI.COMM_SELF)
    assert failure.value.run.summary["status"] == "failed" and len(failure.value.run.rows) == 1
    # without self-contact there is no step bound to trace with: the first failure stands
    calls.clear()
    with pytest.raises(SolveError, match="^first failed$"):
        crater.solve(crater.Params(self_contact=0), MPI.COMM_SELF)
    assert calls == [False]


def test_the_dissertation_specimen_is_a_preset_of_radius_and_element(tmp_path):
    """``--specimen dissertation`` is the section 4a wide (25.40 mm) of Q1-P0 cells (CAX4H); the
    physical puck of P2-P1 cells stays the default; a radius of one's own needs the physical
    preset; the preset survives a sweep's replace(); and the point of a physical run keeps its
    sweep key (the field is ``later``)."""
    from dataclasses import replace

    from bcfem.run.sweep import point_key

    physical, wide = crater.Params(), crater.Params(specimen="dissertation")
    assert physical.specimen_radius == 12.70 and wide.specimen_radius == 25.40
    assert physical.element == "p2p1" and wide.element == "q1p0"
    assert crater.Params(specimen="dissertation", element="q1p0").element == "q1p0"
    assert replace(wide, beta=1.0).specimen_radius == 25.40
    assert point_key({"beta": 1.0}, physical) == point_key({"beta": 1.0}, replace(physical))
    assert point_key({"beta": 1.0}, wide) != point_key({"beta": 1.0}, physical)
    with pytest.raises(ValueError, match="--specimen dissertation sets --specimen-radius"):
        crater.Params(specimen="dissertation", specimen_radius=30.0)
    with pytest.raises(ValueError, match="--specimen must be one of"):
        crater.Params(specimen="large")


def dissertation(**kwargs):
    """A cycle of the dissertation's FE model (``--specimen dissertation``) on this process."""
    return crater.solve(crater.Params(specimen="dissertation", **kwargs), MPI.COMM_SELF)[1]


@slow
@pytest.mark.serial
def test_the_dissertation_model_closes_where_it_says_whatever_beta():
    """Section 7.2.4: eps_m = 0.47, eps_c = 0.43 (the preload whose end-of-unloading -dp reaches
    0.83 p_a, Fig. 7.6b). Vented loading cannot depend on beta = mu / p_a; at beta = 1 the aspect
    0.7 beats 0.85 (Fig. 7.9)."""
    closed = [dissertation(preload=crater.PRELOAD_TO_CLOSURE, beta=beta)["eps_m"] for beta in (0.467, 1.0)]
    assert closed[0] == pytest.approx(0.47, rel=0.03)
    assert closed[1] == pytest.approx(closed[0], rel=5e-3)
    drops = {eps: 1 - dissertation(preload=eps, beta=1.0)["p2_over_pa"] for eps in (0.4, 0.45)}
    assert drops[0.4] < 0.83 < drops[0.45]
    eps_c = 0.4 + (0.83 - drops[0.4]) * 0.05 / (drops[0.45] - drops[0.4])
    assert eps_c == pytest.approx(0.43, rel=0.03)
    optimum, other = (dissertation(preload=crater.PRELOAD_TO_CLOSURE, beta=1.0, alpha=alpha)["F_tilde"]
                      for alpha in (0.7, 0.85))
    assert optimum > other


@slow
@pytest.mark.serial
@pytest.mark.study  # a minute or more: make study
def test_a_reinforced_closure_does_not_depend_on_round_off(tmp_path):
    """Fig. 7.12d's lining (alpha' = 0.03, beta' = 80), closed and unloaded through snaps: the same
    F~ on 1 and 2 ranks, with another BLAS kernel and with a tighter Newton tolerance; physics,
    not round-off, picks its path."""
    args = ("run", "crater", "--specimen", "dissertation", "--preload", "closure", "--beta", "1",
            "--layer-thickness", "0.03", "--layer-stiffness", "80", "--no-plots", "--quiet")
    found = {}
    for name, ranks, extra, env in (("serial", 1, (), None), ("ranks", 2, (), None),
                                    ("kernel", 1, (), {"OPENBLAS_CORETYPE": "Haswell"}),
                                    ("rtol", 1, ("-snes_rtol", "1e-11"), None)):
        done = bcfem(*args, *extra, "--out", tmp_path / name, ranks=ranks, env=env)
        assert done.returncode == 0, done.stderr
        summary = json.loads((tmp_path / name / "summary.json").read_text())
        assert summary["instabilities"], "the path passes no instability: nothing is tested"
        found[name] = summary["F_tilde"]
    for name, value in found.items():
        assert value == pytest.approx(found["serial"], rel=1e-6), (name, found)
