"""The dissertation's double-chamber model (``--chambers membrane``).

On a coarse isolated specimen, loaded to eps = 0.03 (after the protuberance meets the plate):

* the plug's volume: moving the membrane's sidewall node along the sidewall moves V_C1 by the
  revolved triangle between the two plugs (Pappus), and V_C1 + V_C2 = V at rest;
* Fig. 9.9's limits: the exchange model with a small C_V gives the one-cavity model (1) and
  with a large C_V the sealed chambers (2), each within 1 % of the distance between the two,
  in (p_c1 - p_c2)/p_a and (V_c1 - V_c2)/V0; the gas p_1 V_1 + p_2 V_2 is conserved;
* ``mpirun -n 2`` gives the serial cycle (marker ``mpi``);
* bad input exits 2 before meshing.
"""

import functools
import math
from dataclasses import replace

from mpi4py import MPI

import pytest
from helpers import refused

from bcfem.run.runner import solve
from bcfem.scenes import crater_double
from bcfem.scenes.crater_double.membrane import MembraneCycle

#: the equator's height, 0.53 H, on the protuberance and beside it on the sidewall (snapped)
COARSE = crater_double.Params(chambers="membrane", size_wall=0.08, size_contact=0.02, specimen_radius=3.0,
                              specimen_height=3.0, preload=0.03, strain_step=0.015, membrane_sidewall=0.53,
                              membrane_protuberance=0.53, switch_strain=0.03)


class Loading(MembraneCycle):
    unloads = False


@functools.cache
def loaded(cv: float, stiffness: float = 1e-6) -> dict:
    run, _ = solve(Loading(replace(COARSE, exchange_before=cv, membrane_stiffness=stiffness), MPI.COMM_SELF),
                   MPI.COMM_SELF)
    last = run.rows[-1]
    return {"dp": last["p_c1_over_pa"] - last["p_c2_over_pa"], "dV": last["V_c1"] - last["V_c2"],
            "mass": max(r["fluid_law_residual"] for r in run.rows if r["fluid_law_residual"] is not None)}


def test_the_plug_closes_the_chambers():
    """V_C1 + V_C2 = V, and the sidewall node one vertex higher adds the revolved triangle
    (r_b, z_b), (r0, Z_w), (r0, Z_w') to V_C1: 2 pi r_centroid times its area."""
    import numpy as np

    from bcfem.geometry.double_crater import SIDEWALL
    from bcfem.mpi import global_sum
    from bcfem.scenes.crater_double.chamber_membrane import ChamberMembrane
    from bcfem.scenes.crater_double.model import DoubleCrater

    model = DoubleCrater(COARSE.model_inputs(), MPI.COMM_SELF)
    g = model.geometry
    heights = model.split._heights[SIDEWALL]
    zb = g.centre_height
    volumes = []
    for zw in heights[np.searchsorted(heights, zb):][:2]:
        V1, V2 = model.split_at((zw, zb))
        membrane = ChamberMembrane((g.R0, zb), (g.r0, zw))
        membrane.attach(model.u)
        P = membrane.plug_volume()
        volumes.append((zw, V1 + P, V2 - P))
    (z1, a1, b1), (z2, a2, _) = volumes
    assert a1 + b1 == pytest.approx(global_sum(model.volume), rel=1e-12)
    area = 0.5 * (g.r0 - g.R0) * (z2 - z1)
    centroid = (g.R0 + 2 * g.r0) / 3
    assert a2 - a1 == pytest.approx(2 * math.pi * centroid * area, rel=1e-9)


def test_fig_9_9_limits_of_the_exchange_model():
    """Model 3 with C_V = 1e-4 is Model 1 (C_V = 0: one cavity; no membrane stiffness), and with
    C_V = 1e8 Model 2 (no exchange), within 1 % of the distance between them; the gas is
    conserved to round-off at any C_V."""
    one, two = loaded(0.0, 0.0), loaded(math.inf)
    small, large, middle = loaded(1e-4), loaded(1e8), loaded(1.0)
    print({"one": one, "two": two, "small": small, "large": large, "middle": middle})
    for key in ("dp", "dV"):
        span = two[key] - one[key]
        assert abs(span) > 1e-3  # the two models differ
        assert abs(small[key] - one[key]) <= 0.01 * abs(span), key
        assert abs(large[key] - two[key]) <= 0.01 * abs(span), key
        assert min(one[key], two[key]) < middle[key] < max(one[key], two[key]), key
    assert one["dp"] == 0.0
    for case in (small, large, middle):
        assert case["mass"] < 1e-10


@pytest.mark.mpi
def test_two_ranks_equal_serial():
    """Exchange at C_V = 1 to eps_a = 0.015, then sealed (1e4), loaded and unloaded."""
    if MPI.COMM_WORLD.size == 1:
        pytest.skip("needs mpirun -n 2")
    params = replace(COARSE, exchange_before=1.0, switch_strain=0.015)
    rows, summary = crater_double.solve(params, MPI.COMM_WORLD)
    reference, _ = crater_double.solve(params, MPI.COMM_SELF)
    assert [(r["stage"], r["eps"]) for r in rows] == [(r["stage"], r["eps"]) for r in reference]
    for r, ref in zip(rows, reference):
        for key in ("p_c1_over_pa", "p_c2_over_pa", "V_c1", "V_c2", "F_tilde"):
            assert r[key] == pytest.approx(ref[key], rel=1e-8, abs=1e-10), key
    assert summary["switch"]["eps"] == 0.015 and summary["mass_conservation"] < 1e-10


@pytest.mark.parametrize("args, word", [(["--exchange-after", "3"], "chambers membrane"),
                                        (["--chambers", "membrane", "--fluid", "liquid"], "air"),
                                        (["--chambers", "membrane", "--exchange-before=-1"], "exchange-before"),
                                        (["--chambers", "membrane", "--membrane-sidewall", "0.5"], "together"),
                                        (["--chambers", "membrane", "--switch-strain", "1"], "switch-strain"),
                                        (["--chambers", "membrane", "--membrane-stiffness", "2"], "stiffness"),
                                        (["--chambers", "wall"], "chambers"), (["--bottom", "glued"], "bottom")])
def test_bad_input_exits_2_naming_it(tmp_path, args, word):
    assert word in refused("run", "crater-double", *args, out=tmp_path)
