"""What the benchmark scripts share: machine pinning (one core, one thread), the idle wait,
provenance (commit, versions, CPU, date), the worker prologue, Newton counting, Richardson
extrapolation, atomic text output, and reports rendered from templates fed by a benchmark's
CSV and summary JSON."""

from __future__ import annotations

import csv
import datetime
import io
import json
import math
import os
import platform
import re
import shutil
import string
import subprocess
import sys
import time
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

from bcfem.path.roots import bracketed_root  # dolfinx-free

ROOT = Path(__file__).resolve().parents[1]
TEMPLATES = Path(__file__).resolve().parent / "templates"
REPORTS = ROOT / "docs" / "benchmarks"  # <name>.csv, .json, .md, .png of each benchmark

# ----------------------------------------------------------------------------------------
# machine pinning and the worker protocol
# ----------------------------------------------------------------------------------------
#: one BLAS/OpenMP thread: a pinned run must not spread over the other core
ONE_THREAD = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
#: the line a worker prints its result on (JSON after the tag)
RESULT = "RESULT "


def one_core_env(**extra: str) -> dict:
    """The environment of a pinned run: one thread, ``extra`` set, and the user's PETSC_OPTIONS
    left out (the kept results must not depend on them)."""
    env = {**os.environ, **ONE_THREAD, **extra}
    env.pop("PETSC_OPTIONS", None)
    return env


def pinned(cmd: Sequence[str], core: str = "0") -> list[str]:
    """``cmd`` pinned to ``core`` with ``taskset -c`` (unchanged where taskset is missing)."""
    return ["taskset", "-c", core, *cmd] if shutil.which("taskset") else list(cmd)


def worker_prologue():
    """What every worker does first: ``dolfinx_solver`` before dolfinx/petsc4py, then bcfem's
    logging configured quiet on COMM_WORLD. Returns COMM_WORLD."""
    import dolfinx_solver  # noqa: F401  (before dolfinx / petsc4py)
    from mpi4py import MPI

    from bcfem.log import configure

    configure(MPI.COMM_WORLD, quiet=True)
    return MPI.COMM_WORLD


def emit(result: dict) -> None:
    """Print a worker's result for :func:`worker_result` (stdout, one line)."""
    print(RESULT + json.dumps(result), flush=True)


def worker_result(stdout: str) -> dict | None:
    """The last ``RESULT`` line of a worker's stdout, or None."""
    lines = [ln for ln in stdout.splitlines() if ln.startswith(RESULT)]
    return json.loads(lines[-1][len(RESULT):]) if lines else None


def run_worker(script: str, case: dict, core: str = "0", cache: str | None = None) -> dict:
    """Run ``script --worker CASE`` in a fresh process pinned to ``core`` (one thread);
    ``cache`` is an XDG_CACHE_HOME for cold-JIT runs. Returns its ``RESULT`` line plus
    the whole process time."""
    env = one_core_env(**({"XDG_CACHE_HOME": cache} if cache else {}))
    cmd = pinned([sys.executable, script, "--worker", json.dumps(case)], core)
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, env=env, capture_output=True, text=True, cwd=ROOT)
    t_process = time.perf_counter() - t0
    result = worker_result(proc.stdout)
    if proc.returncode != 0 or result is None:
        raise RuntimeError(f"case {case} failed:\n{proc.stdout[-2000:]}\n{proc.stderr[-2000:]}")
    return {**result, "t_process": t_process}


def mpirun_bcfem(args: list[str], ranks: int, quiet_stdout: bool = False) -> None:
    """Run ``mpirun -n RANKS bcfem ARGS`` from the repository's venv (the user's PETSC_OPTIONS
    left out, so that the kept results do not depend on them); raises if it fails."""
    bin_dir = ROOT / ".venv" / "bin"
    env = {**os.environ, "PATH": f"{bin_dir}:{os.environ['PATH']}"}
    env.pop("PETSC_OPTIONS", None)
    subprocess.run([str(bin_dir / "mpirun"), "-n", str(ranks), str(bin_dir / "bcfem"), *args], cwd=ROOT, env=env,
                   check=True, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL if quiet_stdout else None)


def loadavg() -> str:
    """The 1-minute load average ("?" where /proc is missing): were other jobs running?"""
    p = Path("/proc/loadavg")
    return p.read_text().split()[0] if p.exists() else "?"


def busy_cores(seconds: float = 3.0) -> float:
    """Cores kept busy by other processes over ``seconds`` (from /proc/stat; nan if unknown)."""
    def sample():
        fields = [float(x) for x in Path("/proc/stat").read_text().splitlines()[0].split()[1:]]
        return sum(fields), fields[3] + fields[4]  # total, idle + iowait

    try:
        t0, i0 = sample()
        time.sleep(seconds)
        t1, i1 = sample()
    except (OSError, ValueError, IndexError):
        return math.nan
    return (os.cpu_count() or 1) * (1 - (i1 - i0) / (t1 - t0))


def wait_idle(max_wait: float) -> tuple[float, float]:
    """Wait up to ``max_wait`` s for the machine to be idle (< 0.2 busy cores); returns
    (seconds waited, busy cores at the end)."""
    t0 = time.perf_counter()
    busy = busy_cores()
    while busy > 0.2 and time.perf_counter() - t0 < max_wait:
        time.sleep(10)
        busy = busy_cores()
    return time.perf_counter() - t0, busy


def richardson(coarse, fine, order):
    return fine + (fine - coarse) / (2**order - 1)


def fmt(x, spec=".2e"):
    return "" if x is None or (isinstance(x, float) and math.isnan(x)) else format(x, spec)


def csv_text(rows, columns) -> str:
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=columns, extrasaction="ignore", lineterminator="\n")
    w.writeheader()
    for r in rows:
        w.writerow({k: (repr(float(v)) if isinstance(v, float) else v) for k, v in r.items()})  # not np.float64(..)
    return buf.getvalue()


def atomic_text(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp")
    tmp.write_text(text)
    os.replace(tmp, path)


def marks(name: str) -> tuple[str, str]:
    """The markers of a section that another script keeps in a shared markdown file."""
    return f"<!-- {name}:begin -->", f"<!-- {name}:end -->"


def put_section(path: Path, name: str, block: str) -> None:
    """Replace (or append) the marked section ``name`` of the markdown file ``path``;
    ``block`` holds no markers."""
    begin, end = marks(name)
    block = f"{begin}\n{block.strip()}\n{end}"
    text = path.read_text() if path.exists() else ""
    if begin in text:
        text = text[:text.index(begin)] + block + text[text.index(end) + len(end):]
    else:
        text = text.rstrip("\n") + "\n\n" + block + "\n"
    atomic_text(path, text)


def kept_sections(path: Path, names) -> str:
    """The marked sections ``names`` of ``path`` as they are (to carry over a regeneration)."""
    text = path.read_text() if path.exists() else ""
    parts = []
    for begin, end in map(marks, names):
        if begin in text:
            parts.append(text[text.index(begin):text.index(end) + len(end)])
    return "\n\n".join(parts)


def save_figure(fig, path: Path) -> None:
    """Save a driver's figure: the driver is one process, whatever ranks its runs used."""
    from mpi4py import MPI

    from bcfem import io as bcfem_io
    bcfem_io.save_figure(fig, path, MPI.COMM_SELF)


#: the finest meshes whose differences must keep their sign and shrink for Richardson
MONOTONE_MESHES = 4


def observed_order(h, q):
    """p with (q1 - q0)/(q2 - q1) = (h0^p - h1^p)/(h1^p - h2^p) (any mesh ratios), or None."""
    d0, d1 = q[1] - q[0], q[2] - q[1]
    if d0 == 0 or d1 == 0 or d0 * d1 < 0:
        return None
    f = lambda p: (h[0] ** p - h[1] ** p) / (h[1] ** p - h[2] ** p) - d0 / d1  # noqa: E731
    try:
        return bracketed_root(f, 0.05, 12.0, xtol=1e-12)
    except ValueError:
        return None


def reference(series, monotone_meshes: int = MONOTONE_MESHES):
    """The reference F~ of a crater's mesh sequence (rows with ``size_crater`` and ``F_tilde``,
    coarse to fine, ok runs only).

    Richardson extrapolation of the two finest meshes, with the order observed on the three
    finest, if the finest ``monotone_meshes`` values converge monotonically (their differences keep
    one sign and shrink in magnitude) and the order is in [0.5, 8]; else the finest mesh."""
    h = [r["size_crater"] for r in series]
    F = [r["F_tilde"] for r in series]
    d = [b - a for a, b in zip(F, F[1:])]
    tail = d[-(monotone_meshes - 1):]
    monotone = (len(tail) == monotone_meshes - 1 and all(x * tail[0] > 0 for x in tail)
                and all(abs(b) < abs(a) for a, b in zip(tail, tail[1:])))
    sign_changes = sum(1 for a, b in zip(d, d[1:]) if a * b < 0)
    ref = {"finest": series[-1]["size_crater"], "F_finest": F[-1], "monotone": monotone,
           "sign_changes": sign_changes, "differences": d, "meshes": len(series)}
    p = observed_order(h[-3:], F[-3:]) if len(F) >= 3 else None
    ref["order"] = p
    if monotone and p is not None and 0.5 <= p <= 8:
        r = h[-2] / h[-1]
        ref.update(F=F[-1] + (F[-1] - F[-2]) / (r**p - 1), kind="richardson",
                   meshes_used=(h[-2], h[-1]))
    else:
        ref.update(F=F[-1], kind="finest")
    return ref


# ----------------------------------------------------------------------------------------
# provenance
# ----------------------------------------------------------------------------------------
def commit(short: bool = True) -> str:
    """The checkout's HEAD commit ('' outside a git checkout)."""
    cmd = ["git", "rev-parse", *(["--short"] if short else []), "HEAD"]
    return subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True).stdout.strip()


def git_state() -> str:
    """The commit of the bcfem that is imported, and its uncommitted library changes (no paths:
    the docs name no machine's directories)."""
    import importlib.util

    pkg = Path(importlib.util.find_spec("bcfem").origin).parent
    try:
        head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=pkg, capture_output=True,
                              text=True, check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--", "."], cwd=pkg, capture_output=True,
                               text=True, check=True).stdout.split("\n")
        dirty = [ln[3:] for ln in dirty if ln.strip()]
        return f"bcfem @ {head}" + (f" + uncommitted changes in {', '.join(dirty)}" if dirty else "")
    except (OSError, subprocess.CalledProcessError):
        stamp = pkg.parent / "SNAPSHOT"  # a `git archive` export records its commit here
        return f"bcfem ({stamp.read_text().strip() if stamp.exists() else 'not a git checkout'})"


def cpu_name() -> str:
    """The CPU's model name (/proc/cpuinfo; else the platform's)."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


def versions() -> dict:
    """Versions of Python and of the stack a run used (a package that is missing is left out)."""
    from importlib.metadata import PackageNotFoundError, version

    out = {"python": platform.python_version()}
    for name in ("dolfinx-solver-real", "fenics-ufl", "fenics-basix", "fenics-ffcx", "numpy", "scipy", "mpi4py"):
        try:
            out[name] = version(name)
        except PackageNotFoundError:
            pass
    return out


def provenance() -> dict:
    """Where and when a benchmark ran: bcfem's commit, the versions, the CPU, the UTC date and the
    load average; a benchmark keeps it in its summary JSON, and its report renders it."""
    return {"commit": git_state(), "versions": versions(), "cpu": cpu_name(),
            "date": datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d %H:%M UTC"), "load": loadavg()}


def provenance_note(summary: Mapping) -> str:
    """A sentence naming the run's provenance (`` Measured on ...``), or '' for a summary that has
    none (one carried over from a report written before summaries kept it)."""
    prov = summary.get("provenance")
    if not prov:
        return ""
    stack = ", ".join(f"{k} {v}" for k, v in prov["versions"].items())
    return (f" Measured on `{prov['cpu']}` on {prov['date']} (load average {prov['load']}), "
            f"`{prov['commit']}`; {stack}.")


# ----------------------------------------------------------------------------------------
# reports: a template (prose, in benchmarks/templates/) fed by the CSV and the summary
# ----------------------------------------------------------------------------------------
class _Fields(string.Template):
    """``${name}``, ``${name.key}`` (nested summary values) and ``${name:spec}`` (a format spec);
    a bare ``$`` must be written ``$$``."""

    braceidpattern = r"(?a:[_a-z][_a-z0-9]*(?:\.[_a-z0-9-]+)*(?::[^}]*)?)"


class _Lookup(Mapping):
    def __init__(self, values: Mapping):
        self.values = values

    def __getitem__(self, field: str) -> str:
        name, _, spec = field.partition(":")
        value = self.values
        for key in name.split("."):
            value = value[key]
        return format(value, spec) if spec else str(value)

    def __iter__(self):
        return iter(self.values)

    def __len__(self) -> int:
        return len(self.values)


def table(rows: Sequence[Mapping], columns: Sequence[tuple[str, str | Callable]], padded: bool = False) -> str:
    """A Markdown table: ``columns`` are (header, how) with ``how`` a format string of the row's
    fields (``"{cells}"``, ``"{err:.2e}"``) or a function of the row returning its text; ``padded``
    writes the rule under the header as ``| --- |`` instead of ``|---|``."""
    rule = "|" + (" --- |" if padded else "---|") * len(columns)
    lines = ["| " + " | ".join(h for h, _ in columns) + " |", rule]
    for r in rows:
        cells = [how(r) if callable(how) else how.format(**r) for _, how in columns]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


SECTION = re.compile(r"^<!-- section: ([\w-]+) -->\n", re.M)


def template_text(template: str | Path, section: str | None = None) -> str:
    """The text of ``template`` (a path, or a name in benchmarks/templates/): the page before its
    first ``<!-- section: NAME -->`` line, or the named section (up to the next one), which a report
    fills once per case or only when its case arises."""
    path = Path(template)
    if not path.is_absolute() and not path.exists():
        path = TEMPLATES / path
    parts = SECTION.split(path.read_text())
    named = dict(zip(parts[1::2], parts[2::2]))
    return parts[0] if section is None else named[section]


def render(template: str | Path, rows: Sequence[Mapping], summary: Mapping, section: str | None = None,
           **fields) -> str:
    """Fill ``template`` (or its ``section``, see :func:`template_text`) with ``summary`` and
    ``fields`` (tables and derived values, which win); ``rows`` are there as ``${rows}`` (their count)
    for templates that say how many runs there were. Unknown fields raise KeyError."""
    text = template_text(template, section)
    return _Fields(text).substitute(_Lookup({**summary, "rows": len(rows), **fields}))


def read_csv(path: Path) -> list[dict]:
    """The rows of a benchmark's CSV (as :func:`csv_text` wrote them), numbers parsed: an int where
    the text is one, a float where it parses, a bool for True/False, None for an empty cell, else
    the text."""
    def value(text: str):
        if text == "":
            return None
        if text in ("True", "False"):
            return text == "True"
        if re.fullmatch(r"[+-]?\d+", text):
            return int(text)
        try:
            return float(text)
        except ValueError:
            return text

    with open(path, newline="") as f:
        return [{k: value(v) for k, v in row.items()} for row in csv.DictReader(f)]


def write_report(path: Path, text: str) -> None:
    """Write a rendered report atomically, ending in one newline."""
    atomic_text(path, text.rstrip("\n") + "\n")


def write_summary(name: str, summary: Mapping) -> None:
    """docs/benchmarks/<name>.json: what a report needs beside the CSV (references, settings,
    provenance)."""
    atomic_text(REPORTS / f"{name}.json", json.dumps(summary, indent=1, default=float) + "\n")


def render_again(name: str, report: Callable[[list[dict], dict], str]) -> None:
    """``--render-only``: docs/benchmarks/<name>.md rendered again by ``report(rows, summary)`` from
    the <name>.csv and <name>.json that are there; nothing is run."""
    summary = json.loads((REPORTS / f"{name}.json").read_text())
    write_report(REPORTS / f"{name}.md", report(read_csv(REPORTS / f"{name}.csv"), summary))
