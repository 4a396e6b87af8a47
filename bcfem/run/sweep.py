"""Parameter sweeps: independent points spread over MPI ranks, resumable, one CSV.

Each rank solves points on its own communicator (``comm.Split`` by rank, so
every point is a serial solve and the map does not depend on the number of
ranks). Points are handed out as the ranks become free: every rank walks the
points in order and takes the first one no rank has claimed (an exclusively
created file), so one slow point does not leave the other ranks idle; :func:`run_pool`
does so across several sweeps.

Every finished point is written at once to ``points/<key>.json`` (atomically),
so a rerun skips it; a failed point is recorded with its reason and the solver
budgets it had, never dropped (``--retry-failed`` solves it again, and so does a
rerun with a larger budget). Rank 0 then gathers ``sweep.csv`` and, if it solved
anything, ``timing.json`` (points solved and reused, ranks, wall time of this
run). Each point also keeps its own ``solve_time_s`` and ``forms_compiled``, so the cost of a map
solved over several (interrupted) runs is known. ``summary.json`` gives the sweep's
``status``: ``ok``, ``failed`` (some point failed; ``failures`` counts each reason) or
``interrupted`` (by a signal: the finished points are kept, a rerun solves the rest).
"""

from __future__ import annotations

import dataclasses
import itertools
import json
import logging
import math
import os
import re
import shutil
import time
import traceback
import uuid
from pathlib import Path

import numpy as np

from bcfem import interrupt, io, jit
from bcfem.log import logger

#: kept in a point's record, not in sweep.csv (which depends on the results alone)
RECORD_ONLY = {"budgets", "solve_time_s", "forms_compiled", "resumed_from"}
#: seconds between two checkpoints of a point's paths (a killed sweep resumes each point from its own)
CHECKPOINT_EVERY = 60.0


#: the most points one sweep may hold
MAX_POINTS = 10_000


def parse_axis(text: str) -> tuple[str, np.ndarray | list]:
    """``name=start:stop:count`` (inclusive, linear) or ``name=v1,v2,...`` (numbers, or the
    words of a choice such as ``contact=separable,bonded``)."""
    if "=" not in text:
        raise ValueError(f"--grid {text}: an axis is NAME=START:STOP:COUNT or NAME=V1,V2,...")
    name, spec = text.split("=", 1)
    name = name.strip().replace("-", "_")
    if ":" in spec:
        parts = spec.split(":")
        try:
            start, stop = float(parts[0]), float(parts[1])
            count = int(parts[2]) if len(parts) == 3 else None
        except ValueError:
            count = None
        if count is None:
            raise ValueError(f"--grid {text}: need START:STOP:COUNT, two numbers and a whole number")
        if not 1 <= count <= MAX_POINTS:
            raise ValueError(f"--grid {text}: the count must be in [1, {MAX_POINTS}] (got {count})")
        return name, np.linspace(start, stop, count)
    values = [v.strip() for v in spec.split(",")]
    if "" in values:
        raise ValueError(f"--grid {text}: an empty value")
    try:
        return name, np.array([float(v) for v in values])
    except ValueError:
        return name, values  # words, or numbers among named values (preload=closure,0.1)


def parse_range(name: str, spec: str) -> np.ndarray:
    """``start:stop:step``, both ends included (e.g. ``0:0.5:0.025``, 21 values)."""
    try:
        start, stop, step = (float(v) for v in spec.split(":"))
    except ValueError:
        raise ValueError(f"--{name.replace('_', '-')} {spec}: need start:stop:step") from None
    if not (math.isfinite(start) and math.isfinite(stop) and step > 0 and stop >= start):
        raise ValueError(f"--{name.replace('_', '-')} {spec}: need finite ends, step > 0 and stop >= start")
    count = (stop - start) / step
    if not count < MAX_POINTS:  # also an overflow to inf
        raise ValueError(f"--{name.replace('_', '-')} {spec}: more than {MAX_POINTS} values")
    count = round(count)
    if count + 1 > MAX_POINTS:
        raise ValueError(f"--{name.replace('_', '-')} {spec}: {count + 1} values, more than {MAX_POINTS}")
    if abs(start + count * step - stop) > 1e-9 * max(1.0, abs(stop)):
        raise ValueError(f"--{name.replace('_', '-')} {spec}: the steps of {step:g} from {start:g} miss {stop:g}")
    return start + step * np.arange(count + 1)


def point_key(values: dict, params=None) -> str:
    """File name of a point: its grid values, plus a digest of every other parameter, so a
    rerun with different settings never reuses stale points. Solver budgets are left out: they
    decide whether a point gets through, not its result, and so is a parameter added after the
    maps were solved, at its default, so that the points solved before it came stay valid (the
    fields' ``budget`` and ``later`` metadata, :func:`bcfem.params.describe`)."""
    key = "_".join(f"{k}={v if isinstance(v, str) else format(v, '.12g')}" for k, v in sorted(values.items()))
    if params is None:
        return key
    import hashlib

    budgets = _budgets(params)
    later = {f.name: f.default for f in dataclasses.fields(params) if f.metadata.get("later")}
    settings = {k: v for k, v in dataclasses.asdict(params).items()
                if k not in values and k not in budgets and not (k in later and v == later[k])}
    digest = hashlib.sha1(json.dumps(settings, sort_keys=True, default=str).encode()).hexdigest()[:10]
    return f"{key}_{digest}"


def _numbers(base, name: str, values):
    """An axis of words for a numeric field as numbers: each a number or one of the field's named
    values (``preload=closure,0.1``)."""
    field = next((f for f in dataclasses.fields(base) if f.name == name), None)
    if not isinstance(values, list) or field is None or isinstance(getattr(base, name), str):
        return values
    words = field.metadata.get("words", {})
    numbers = []
    for v in values:
        try:
            numbers.append(words[v] if v in words else float(v))
        except ValueError:
            names = f" nor one of {', '.join(words)}" if words else ""
            raise ValueError(f"--grid {name}: {v!r} is not a number{names}") from None
    return np.array(numbers)


def grid_points(base, axes: list[tuple[str, np.ndarray | list]]) -> list:
    """Every combination of the axes, as validated parameter sets (validation happens here,
    before any solve, so a bad grid fails at once)."""
    names = [a[0] for a in axes]
    fields = {f.name: getattr(base, f.name) for f in dataclasses.fields(base)}
    for name, values in axes:
        if name not in fields:
            raise ValueError(f"--grid {name}: not a parameter of the scene")
        if names.count(name) > 1:
            raise ValueError(f"--grid {name}: the axis is given twice")
    axes = [(name, _numbers(base, name, values)) for name, values in axes]
    for name, values in axes:
        if isinstance(fields[name], str) != isinstance(values, list):
            kind = "words" if isinstance(fields[name], str) else "numbers"
            raise ValueError(f"--grid {name}: takes {kind} (got {', '.join(map(str, values))})")
    total = math.prod(len(a[1]) for a in axes)
    if total > MAX_POINTS:
        raise ValueError(f"--grid: {total} points, more than {MAX_POINTS}")
    points = []
    for combo in itertools.product(*(a[1] for a in axes)):
        setting = dict(zip(names, (v if isinstance(v, str) else float(v) for v in combo)))
        try:
            points.append((setting, dataclasses.replace(base, **setting)))
        except ValueError as err:
            raise ValueError(f"--grid point {point_key(setting)}: {err}") from None
    return points

def _budgets(params) -> dict:
    """The solver budgets of ``params`` (its fields marked ``budget``) and their values."""
    return {f.name: getattr(params, f.name) for f in dataclasses.fields(params) if f.metadata.get("budget")}


def _rerun(row: dict, budgets: dict, retry_failed: bool) -> bool:
    """A recorded point is solved again only if it failed and either ``retry_failed`` or a
    budget has grown since (a point failed with an unrecorded budget counts as grown)."""
    if row.get("status") == "ok":
        return False
    recorded = row.get("budgets", {})
    return retry_failed or any(k not in recorded or v > recorded[k] for k, v in budgets.items())


def run(points, solve_point, out: Path, comm, retry_failed: bool = False,
        checkpoint_every: float = CHECKPOINT_EVERY) -> list[dict]:
    """Solve ``points`` (from :func:`grid_points`) over the ranks of ``comm``; return all rows.

    Args:
        solve_point: ``solve_point(params, comm) -> dict`` of results for one point.
        retry_failed: solve again the points recorded as failed (else they are kept as
            they are: a failure is a result, and re-solving it can take long).
        checkpoint_every: seconds between two checkpoints of a point's paths.
    """
    return run_pool([(points, solve_point, out)], comm, retry_failed, checkpoint_every)[0]


def run_pool(sweeps, comm, retry_failed: bool = False, checkpoint_every: float = CHECKPOINT_EVERY) -> list[list[dict]]:
    """Several sweeps, ``[(points, solve_point, out), ...]``, as one pool of points: a rank
    that finds no unclaimed point left in one sweep goes on to the next, rather than waiting
    for the slowest point of each. Each sweep's ``sweep.csv`` and ``timing.json`` are written
    once all are solved; a pooled sweep's ``wall_time_s`` is the pool's, and its own cost is
    ``point_solve_time_s``, the sum of its points' solve times. Returns each sweep's rows
    (see :func:`run`)."""
    t0 = time.perf_counter()
    outs = [Path(out) for _, _, out in sweeps]
    if len({out.resolve() for out in outs}) != len(outs):  # their claims would collide
        raise ValueError(f"run_pool: each sweep needs its own output directory (got {', '.join(map(str, outs))})")
    if comm.rank == 0:
        for out in outs:
            (out / "points").mkdir(parents=True, exist_ok=True)
    # this run's claims (an interrupted run leaves its directory behind, ignored by the next)
    tag = comm.bcast(uuid.uuid4().hex[:12] if comm.rank == 0 else None)
    claims = [out / "points" / f".claims-{tag}" for out in outs]
    if comm.rank == 0:
        for directory in claims:
            directory.mkdir()
    comm.barrier()
    own = comm.Split(color=comm.rank, key=0)
    counts = [_solve_claimed(points, solve_point, out / "points", directory, own, retry_failed, checkpoint_every)
              for (points, solve_point, _), out, directory in zip(sweeps, outs, claims)]
    own.Free()
    with interrupt.deferred():  # a signal from here on: the flag only, so that no rank is left waiting
        counts = [(comm.allreduce(done), comm.allreduce(skipped), comm.allreduce(seconds))
                  for done, skipped, seconds in counts]
        signum = interrupt.received(comm)
        if signum:
            for (points, _, _), out, directory in zip(sweeps, outs, claims):
                _stopped(points, out, directory, comm, signum)
            raise interrupt.Interrupted(signum)
        comm.barrier()
        wall = time.perf_counter() - t0
        return [_gather(points, out, directory, comm, count, wall, len(sweeps))
                for (points, _, _), out, directory, count in zip(sweeps, outs, claims, counts)]


def _solve_claimed(points, solve_point, point_dir: Path, claims: Path, own, retry_failed: bool, every: float):
    """The points of one sweep this rank claims first: (solved, reused, their solve seconds)."""
    done = skipped = 0
    seconds = 0.0
    try:
        for index, (values, params) in enumerate(points):
            if interrupt.requested():
                break  # the other sweeps' points are left too
            key = point_key(values, params)
            try:
                os.close(os.open(claims / key, os.O_CREAT | os.O_EXCL | os.O_WRONLY))
            except FileExistsError:
                continue  # another rank has taken it
            path = point_dir / f"{key}.json"
            budgets = _budgets(params)
            if path.exists() and not _rerun(io.read_json(path), budgets, retry_failed):
                skipped += 1  # finished before
                continue
            row = _solve_point(values, params, solve_point, budgets, own, point_dir / f"{key}.checkpoint", every)
            seconds += row["solve_time_s"]
            io.write_json(path, row, own)
            done += 1
            logger.info(f"sweep: point {index + 1}/{len(points)} {point_key(values)}: {row['status']}")
    except interrupt.Interrupted:
        pass  # the point being solved is not written: a rerun solves it
    return done, skipped, seconds


def _solve_point(values: dict, params, solve_point, budgets: dict, own, checkpoint: Path, every: float) -> dict:
    """One point's record: its results, or why it failed. Its solves write checkpoints into
    ``checkpoint``, from which a point killed or interrupted before its record was written goes
    on in the next run; a point recorded needs them no more."""
    from bcfem.path.checkpoint import Checkpoints, ResumeError
    from bcfem.run.resume import checkpointed

    level = logger.level
    logger.setLevel(logging.WARNING)  # no per-step progress from inside a point
    jit.install()
    start, compiled = time.perf_counter(), jit.tally().compiled
    identity = {**dataclasses.asdict(params), **values} \
        if dataclasses.is_dataclass(params) and not isinstance(params, type) else values
    try:
        checkpoints = Checkpoints(checkpoint, own, every, True, identity)
    except ResumeError:  # another point's (another base): from the start
        checkpoints = Checkpoints(checkpoint, own, every, False, identity)
    resumed_from = checkpoints.latest_key
    try:
        with checkpointed(checkpoints):
            row = {**values, "status": "ok", "reason": "", **solve_point(params, own),
                   **({"resumed_from": resumed_from} if resumed_from else {})}
    except Exception as error:  # recorded, never dropped
        row = {**values, "status": "failed", "reason": f"{type(error).__name__}: {error}",
               **({"budgets": budgets} if budgets else {})}
        logger.debug(traceback.format_exc())
    finally:
        logger.setLevel(level)
    checkpoints.remove()
    row["solve_time_s"] = time.perf_counter() - start  # kept with the point: survives an interrupted run
    row["forms_compiled"] = jit.tally().compiled - compiled  # a sweep compiles the forms of one point
    return row


def failures(rows: list[dict]) -> dict[str, int]:
    """How many points failed for each reason, the most frequent first. Reasons that differ
    only in their numbers (the load where a path ended) count as one, under the first."""
    counts: dict[str, int] = {}
    first: dict[str, str] = {}
    for row in rows:
        if row["status"] != "ok":
            kind = re.sub(r"\d+(\.\d*)?(e[-+]?\d+)?", "#", row["reason"])
            first.setdefault(kind, row["reason"])
            counts[kind] = counts.get(kind, 0) + 1
    return {first[kind]: n for kind, n in sorted(counts.items(), key=lambda item: -item[1])}


def clear_claims(out: Path) -> None:
    """Remove the claims of earlier runs killed before they could (call it only while no
    other run solves into ``out``: under its lock)."""
    for directory in (Path(out) / "points").glob(".claims-*"):
        shutil.rmtree(directory, ignore_errors=True)


def _stopped(points, out: Path, claims: Path, comm, signum: int) -> None:
    """Rank 0 records an interrupted sweep: its claims go, its finished points stay."""
    if comm.rank != 0:
        return
    shutil.rmtree(claims, ignore_errors=True)
    finished = sum((out / "points" / f"{point_key(values, params)}.json").exists() for values, params in points)
    io.write_json(out / "summary.json", {"status": "interrupted", "error": f"interrupted by "
                                         f"{interrupt.Interrupted(signum)}", "points": len(points),
                                         "finished": finished}, comm)


def _gather(points, out: Path, claims: Path, comm, count, wall: float, pooled: int) -> list[dict]:
    """Rank 0 writes one sweep's ``sweep.csv`` (and ``timing.json`` if it solved anything);
    every rank gets its rows."""
    total_done, total_skipped, seconds = count
    rows = []
    if comm.rank == 0:
        shutil.rmtree(claims)
        for values, params in points:
            rows.append(io.read_json(out / "points" / f"{point_key(values, params)}.json"))
        # a point's nested records (dicts) stay in its JSON file, out of the CSV
        columns = sorted({k for r in rows for k, v in r.items() if not isinstance(v, dict)} - RECORD_ONLY,
                         key=lambda k: (k in ("status", "reason"), k))
        io.write_csv(out / "sweep.csv", rows, comm, columns)
        if total_done:  # a rerun that solved nothing keeps the timing of the run that did
            io.write_json(out / "timing.json", {
                "solved": total_done, "reused": total_skipped, "failed": sum(r["status"] != "ok" for r in rows),
                "ranks": comm.size, "wall_time_s": wall, "point_solve_time_s": seconds, "pooled_sweeps": pooled,
                "core_seconds_per_solved_point": (wall * comm.size if pooled == 1 else seconds) / total_done},
                comm)
        reasons = failures(rows)
        error = f"{sum(reasons.values())} of {len(rows)} points failed" if reasons else None
        io.write_json(out / "summary.json", {"status": "failed" if reasons else "ok", "error": error,
                                             "points": len(rows), "finished": len(rows),
                                             "failed": sum(reasons.values()), "failures": reasons}, comm)
    logger.info(f"sweep: {total_done} points solved, {total_skipped} reused, "
                f"{sum(r['status'] != 'ok' for r in rows)} failed -> {out / 'sweep.csv'}")
    return comm.bcast(rows, root=0)


def _computed(rows, panels):
    """The panels whose column some point has (a scene's optional outputs, e.g. the crater's
    symmetry class, only with --waves); all of them if no point has any."""
    return [p for p in panels if any(r.get(p[0]) is not None for r in rows)] or panels


#: panels per row of a sweep's figure: more wrap onto further rows
PANEL_COLUMNS = 4


def _panel_grid(plt, count: int, width: float, height: float):
    """A figure of ``count`` panels (each ``width`` x ``height`` inches) in rows of at most
    PANEL_COLUMNS, and its panels in reading order; the cells left over are hidden."""
    lines = -(-count // PANEL_COLUMNS)
    columns = -(-count // lines)  # balanced: 9 panels as 3 x 3, not 4 + 4 + 1
    fig, axes = plt.subplots(lines, columns, figsize=(width * columns, height * lines), squeeze=False)
    axes = axes.ravel()
    for ax in axes[count:]:
        ax.set_visible(False)
    return fig, list(axes[:count])


def contour_maps(rows, x: str, y: str, panels: list[tuple[str, str]], title: str, path, comm):
    """One filled contour per (column, label) over the (x, y) grid; failed points are blank."""
    if comm.rank != 0:
        return
    import textwrap

    from bcfem.plots import pyplot

    plt = pyplot()
    panels = _computed(rows, panels)
    xs = sorted({r[x] for r in rows})
    ys = sorted({r[y] for r in rows})
    fig, axes = _panel_grid(plt, len(panels), 4.2, 3.6)
    for ax, (column, label) in zip(axes, panels):
        Z = np.full((len(ys), len(xs)), np.nan)
        for r in rows:
            value = r.get(column)
            if r["status"] == "ok" and value is not None:
                Z[ys.index(r[y]), xs.index(r[x])] = value
        ax.set_title(textwrap.fill(label, 44), fontsize=9)
        ax.set_xlabel(x)
        ax.set_ylabel(y)
        if np.isnan(Z).all() or np.nanmin(Z) == np.nanmax(Z):  # no contours to draw
            note = "no converged point" if np.isnan(Z).all() else f"{np.nanmin(Z):.6g} at every point"
            ax.set(xlim=(xs[0], xs[-1]), ylim=(ys[0], ys[-1]))
            ax.text(0.5, 0.5, note, ha="center", va="center", transform=ax.transAxes)
            continue
        cs = ax.contourf(xs, ys, Z, levels=14, cmap="viridis")
        ax.contour(xs, ys, Z, levels=cs.levels, colors="k", linewidths=0.3)
        fig.colorbar(cs, ax=ax)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    io.save_figure(fig, path, comm)


def curves(rows, x: str, panels: list[tuple[str, str]], title: str, path, comm):
    """One panel per (column, label) against the single grid axis; failed points are gaps."""
    if comm.rank != 0:
        return
    import textwrap

    from bcfem.plots import pyplot

    plt = pyplot()
    panels = _computed(rows, panels)
    fig, axes = _panel_grid(plt, len(panels), 3.4, 3.2)
    xs = [r[x] for r in rows]
    for ax, (column, label) in zip(axes, panels):
        ax.plot(xs, [r.get(column) if r["status"] == "ok" else np.nan for r in rows], "-o", ms=3)
        ax.set_xlabel(x)
        ax.set_ylabel(textwrap.fill(label, 32), fontsize=9)
        ax.grid(alpha=0.3)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    io.save_figure(fig, path, comm)
