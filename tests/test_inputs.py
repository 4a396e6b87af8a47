"""Every input of every scene, sweep and fit, drawn at random (hypothesis): inside, at and
outside its range, NaN, ±inf, 1e308 and words. Bad input exits 2 in one line naming the flag,
before anything is written; legal input is refused only by a documented cross-condition, also
naming a flag. The fast tier draws a sample; ``make test-all`` the full draw, and runs legal
draws through the command line: exit 0, or exit 1 with ``status: failed`` and a reason, or, past
a time limit, SIGINT and ``status: interrupted`` (exit 130), never a traceback.
"""

import dataclasses
import json
import math
import os
import signal
import subprocess
import sys
import time

import pytest
from helpers import BIN, refused
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from bcfem.params import bound_of, flag
from bcfem.scenes import REGISTRY, STUDIES

#: drawn in the same order on every machine; explore with --hypothesis-seed
FAST = settings(max_examples=15, deadline=None, derandomize=True, database=None,
                suppress_health_check=[HealthCheck.too_slow])
#: the full draw (make test-all: the marker 'slow' is selected there)
FULL = settings(FAST, max_examples=200)
DRAW = FULL if os.environ.get("BCFEM_FULL_DRAW") else FAST

SPECIALS = [math.nan, math.inf, -math.inf, 1e308, -1e308]


def parameters():
    """(scene, field name, bound or choices) for every flag of every scene."""
    for scene in REGISTRY:
        params = REGISTRY[scene].Params
        defaults = params()
        for f in dataclasses.fields(params):
            value = getattr(defaults, f.name)
            if dataclasses.is_dataclass(value) or f.metadata.get("unit") == "path":
                continue  # a file's checks are the scene's own tests
            choices = f.metadata.get("choices")
            yield scene, f.name, bound_of(params, f.name) or list(choices or [])


PARAMETERS = list(parameters())


def test_every_numeric_parameter_has_a_finite_bound():
    numeric = [(s, n) for s, n, b in PARAMETERS if not isinstance(b, list)]
    assert len(numeric) > 60
    for scene, name, bound in PARAMETERS:
        assert bound, f"{scene} {flag(name)} has neither a bound nor choices"
        if not isinstance(bound, list):
            assert math.isfinite(bound.low) and math.isfinite(bound.high), (scene, name)


def outside(bound):
    """Values the bound refuses: past either end, at an open end, NaN, ±inf, 1e308, words,
    fractions of an integer parameter."""
    past = st.one_of(st.floats(max_value=bound.low, exclude_max=not bound.open_low),
                     st.floats(min_value=bound.high, exclude_min=not bound.open_high),
                     st.sampled_from(SPECIALS),
                     st.floats(bound.low, bound.high).filter(lambda x: bound.integer and x != int(x)))
    return past.filter(lambda x: not bound.admits(x))


def inside(bound):
    if bound.integer:
        values = st.integers(math.ceil(bound.low), math.floor(bound.high))
    else:
        values = st.floats(bound.low, bound.high, exclude_min=bound.open_low, exclude_max=bound.open_high)
    return st.one_of(values, st.sampled_from(bound.also)) if bound.also else values


def text(value) -> str:
    return repr(value) if isinstance(value, float) else str(value)


def command(scene: str, name: str, value, kind: str = "run") -> list[str]:
    """A command that gives ``value`` to the flag of ``name`` in a run, sweep or fit."""
    if kind == "sweep":
        return ["sweep", scene, "--grid", f"{name}={text(value)}"]
    if kind == "fit":
        return ["fit", scene, "--aspect", "0.5", "--P1", "3", flag(name), text(value)]
    return ["run", scene, flag(name), text(value)]


KINDS = {"run": list(REGISTRY), "sweep": list(STUDIES), "fit": ["blister-rigid"]}
CASES = [(kind, scene, name, bound) for kind, scenes in KINDS.items()
         for scene, name, bound in PARAMETERS if scene in scenes]


@pytest.mark.parametrize("kind, scene, name, bound", CASES,
                         ids=[f"{k}-{s}-{n}" for k, s, n, _ in CASES])
def test_a_value_out_of_range_exits_2_naming_the_flag(tmp_path_factory, kind, scene, name, bound):
    if isinstance(bound, list):  # a word that is not a choice (and not a list of them, in a grid)
        values = st.text("abcdefghijklmnopqrstuvwxyz-_ 0123456789", max_size=8).filter(
            lambda w: w not in bound and not w.startswith("-"))
    else:
        values = st.one_of(outside(bound), st.sampled_from(["abc", "0x", "1e", ""]))

    @DRAW
    @given(value=values)
    def check(value):
        line = refused(*command(scene, name, value, kind), "--quiet", out=tmp_path_factory.mktemp("bad") / "out")
        where = "--grid" if kind == "sweep" else flag(name)
        assert where in line and "Traceback" not in line, line

    check()


@pytest.mark.parametrize("scene, name, bound", [p for p in PARAMETERS if not isinstance(p[2], list)],
                         ids=[f"{s}-{n}" for s, n, b in PARAMETERS if not isinstance(b, list)])
def test_a_value_in_range_is_taken_or_refused_by_a_named_condition(scene, name, bound):
    params = REGISTRY[scene].Params

    @DRAW
    @given(value=inside(bound))
    def check(value):
        try:
            made = params(**{name: value})
        except ValueError as err:  # a cross-condition: v-start < v-max, the crater fits, ...
            assert "--" in str(err), str(err)
        else:
            assert getattr(made, name) == value

    check()


@pytest.mark.parametrize("target", ["aspect", "P1"])
def test_a_fit_target_out_of_range_exits_2(tmp_path_factory, target):
    bound = STUDIES["blister-rigid"].FIT_TARGETS[target][1]

    @DRAW
    @given(value=st.one_of(outside(bound), st.sampled_from(["abc", ""])))
    def check(value):
        targets = {"aspect": "0.5", "P1": "3", target: text(value)}
        argv = ["fit", "blister-rigid", *(x for k, v in targets.items() for x in (f"--{k}", v))]
        assert f"--{target}" in refused(*argv, out=tmp_path_factory.mktemp("fit") / "out")

    check()


# -- legal draws through the command line (make test-all) ----------------------------------------
#: a run still going after this long is interrupted: the contract then is status 'interrupted'
PATIENCE_S = 25
#: cheap settings the drawn value replaces; a drawn parameter keeps its other defaults
CHEAP = {"blister-rigid": ["--cells", "20", "--v-max", "1"],
         "blister-soft": ["--size-contact", "0.05", "--v-max", "0.5"],
         "crater": ["--size-crater", "0.16", "--preload", "0.1", "--strain-step", "0.05"],
         "crater-double": ["--size-wall", "0.16", "--size-contact", "0.04", "--preload", "0.05",
                           "--strain-step", "0.05"],
         "droplet-soft": ["--size-contact", "0.05"],
         "blister-3d": ["--size", "0.25", "--v-max", "0.3"],
         "crater-cell": ["--size-wall", "0.5", "--size-rim", "0.2", "--size-far", "1.5", "--preload", "0.05",
                         "--strain-step", "0.05"],
         "crater-sector": ["--size-wall", "0.5", "--size-far", "1.5", "--steps", "1", "--drawn-step", "0.02"]}


def run_to_a_status(argv: list[str], out) -> tuple[int, dict | None, str]:
    """Run ``bcfem argv`` as a user would; past :data:`PATIENCE_S` send SIGINT."""
    env = {**os.environ, "PATH": f"{BIN}{os.pathsep}{os.environ['PATH']}"}
    process = subprocess.Popen([str(BIN / "bcfem"), *argv, "--out", str(out), "--quiet", "--no-plots"],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    try:
        _, stderr = process.communicate(timeout=PATIENCE_S)
    except subprocess.TimeoutExpired:
        process.send_signal(signal.SIGINT)
        _, stderr = process.communicate(timeout=300)  # a signal during meshing waits for gmsh
    summary = out / "summary.json"
    return process.returncode, json.loads(summary.read_text()) if summary.exists() else None, stderr


@pytest.mark.slow
@pytest.mark.serial
@pytest.mark.parametrize("scene", list(REGISTRY))
def test_legal_draws_end_in_a_status_never_a_traceback(tmp_path_factory, scene):
    numeric = [(n, b) for s, n, b in PARAMETERS if s == scene]
    strategy = st.one_of(*(st.tuples(st.just(n), inside(b) if not isinstance(b, list) else st.sampled_from(b))
                           for n, b in numeric))
    started = time.perf_counter()

    @settings(FAST, max_examples=4)
    @given(drawn=strategy)
    def check(drawn):
        name, value = drawn
        cheap = CHEAP[scene]
        if flag(name) in cheap:
            i = cheap.index(flag(name))
            cheap = cheap[:i] + cheap[i + 2:]
        argv = ["run", scene, *cheap, flag(name), text(value)]
        code, summary, stderr = run_to_a_status(argv, tmp_path_factory.mktemp("legal"))
        assert "Traceback" not in stderr, (argv, stderr[-2000:])
        if code == 2:  # a documented cross-condition with the cheap settings
            assert len(stderr.splitlines()) == 1 and "--" in stderr, (argv, stderr)
            return
        assert code in (0, 1, 130), (argv, code, stderr[-2000:])
        assert summary is not None, argv
        status = {0: "ok", 1: "failed", 130: "interrupted"}[code]
        assert summary["status"] == status, (argv, summary["status"])
        if status != "ok":
            assert summary["error"], argv

    check()
    print(f"{scene}: legal draws in {time.perf_counter() - started:.0f} s", file=sys.stderr)
