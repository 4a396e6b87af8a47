"""What the form compiler costs a user, before and after a change: docs/benchmarks/compile-once.{csv,md}.

Each case is a short sequence of ``bcfem`` commands run one after another from an empty FFCx
cache (``XDG_CACHE_HOME`` a new folder), as a user varies one parameter: a first value, a new
value, the new value again (warm). Every command is a whole process pinned to one core; the
forms it compiled are the new modules in the cache (each compiled form or expression adds one
``.so``), the measure that needs nothing of the version under test. Both versions run each
case in turn: ``--before`` (checked out into a temporary git worktree) and the working tree.

Usage (from the repository root, on an otherwise idle machine)::

    .venv/bin/python benchmarks/compile_once.py --before COMMIT   # about 8 min on 2 cores
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from common import ROOT, atomic_text, cpu_name, csv_text, loadavg, one_core_env, pinned
from speed import worktree

BCFEM = ROOT / ".venv" / "bin" / "bcfem"
OUT = ROOT / "docs" / "benchmarks"

#: case -> its commands (the arguments after ``bcfem``), run in this order in one empty cache
CASES = {
    "crater, new beta": [["run", "crater", "--preload", "0.1", "--beta", b] for b in ("0.5", "0.61", "0.61")],
    "blister-rigid, new Jm and alpha": [
        ["run", "blister-rigid", "--material", "gent", "--v-max", "2", "--Jm", jm, "--alpha", a]
        for jm, a in (("100", "0.5"), ("50", "0.7"), ("50", "0.7"))],
    "blister-soft, new stiffness ratio": [["run", "blister-soft", "--stiffness-ratio", k] for k in ("2", "3", "3")],
    "crater-cell, new beta": [["run", "crater-cell", "--beta", b] for b in ("0.5", "0.61", "0.61")],
    "crater sweep, 3 values of beta": [["sweep", "crater", "--preload", "0.1", "--grid", "beta=0.4,0.5,0.6"]],
}
STEPS = ("first value", "new value", "new value again")


def modules(cache: Path) -> int:
    """Compiled modules in an FFCx cache."""
    return sum(1 for _ in cache.rglob("*.so")) if cache.exists() else 0


def run_case(code: Path, case: str, scratch: Path) -> list[dict]:
    cache = scratch / "cache"
    env = one_core_env(XDG_CACHE_HOME=str(cache))
    env["PYTHONPATH"] = str(code)
    rows = []
    for k, args in enumerate(CASES[case]):
        out = scratch / f"out{k}"
        extra = ["--quiet"] + (["--no-plots"] if args[0] == "run" else [])
        before = modules(cache)
        t0 = time.perf_counter()
        proc = subprocess.run(pinned([str(BCFEM), *args, "--out", str(out), *extra]), env=env,
                              cwd=tempfile.gettempdir(), capture_output=True, text=True)
        wall = time.perf_counter() - t0
        if proc.returncode != 0:
            raise RuntimeError(f"{case}: bcfem {' '.join(args)} with {code} failed:\n{proc.stderr[-2000:]}")
        rows.append({"case": case, "step": STEPS[k] if len(CASES[case]) > 1 else "3 points, one process",
                     "command": "bcfem " + " ".join(args), "wall_s": wall, "forms_compiled": modules(cache) - before})
    return rows


def measure(before: Path) -> list[dict]:
    rows = []
    for case in CASES:
        for version, code in (("before", before), ("after", ROOT)):
            scratch = Path(tempfile.mkdtemp(prefix="bcfem-compile-"))
            try:
                rows += [{"version": version, **row} for row in run_case(code, case, scratch)]
            finally:
                shutil.rmtree(scratch, ignore_errors=True)
            print(f"{case}, {version}: " + ", ".join(f"{r['wall_s']:.1f} s / {r['forms_compiled']} forms"
                                                     for r in rows if r["case"] == case and r["version"] == version),
                  flush=True)
    return rows


def report(rows: list[dict], commit: str) -> str:
    lines = ["# Benchmark: compile once", "",
             "Regenerate with `.venv/bin/python benchmarks/compile_once.py --before COMMIT`. Measured on "
             f"`{cpu_name()}` (load average {loadavg()} at the end), before = {commit}, after = the working tree.",
             "", "Each case runs its commands one after another from an empty FFCx cache; each command is a whole "
             "process pinned to one core. *forms* counts the modules the command added to the cache (a compiled "
             "form or expression each). The first value pays the compiler; after the change a new value pays "
             "nothing, and runs as fast as the same value again.", "",
             "| case | step | before: wall [s] | forms | after: wall [s] | forms |", "|---|---|---|---|---|---|"]
    for case in CASES:
        pairs = {}
        for r in rows:
            if r["case"] == case:
                pairs.setdefault(r["step"], {})[r["version"]] = r
        for step, p in pairs.items():
            b, a = p["before"], p["after"]
            lines.append(f"| {case} | {step} | {b['wall_s']:.1f} | {b['forms_compiled']} | {a['wall_s']:.1f} | "
                         f"{a['forms_compiled']} |")
    lines += ["", "The commands:", ""] + [f"- {case}: `" + "`, then `".join(
        "bcfem " + " ".join(c) for c in commands) + "`" for case, commands in CASES.items()]
    return "\n".join(lines) + "\n"


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", required=True, help="the commit to compare with")
    args = parser.parse_args(argv)
    commit = subprocess.run(["git", "rev-parse", "--short", args.before], cwd=ROOT, capture_output=True,
                            text=True, check=True).stdout.strip()
    before = worktree(args.before)
    try:
        rows = measure(before)
    finally:
        subprocess.run(["git", "worktree", "remove", "--force", str(before)], cwd=ROOT, capture_output=True)
    columns = ["case", "step", "version", "command", "wall_s", "forms_compiled"]
    atomic_text(OUT / "compile-once.csv", csv_text(rows, columns))
    atomic_text(OUT / "compile-once.md", report(rows, commit))
    print(f"wrote {OUT / 'compile-once.md'}")


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).parent))
    main()
