"""Command line: ``bcfem run|sweep|fit SCENE [--param value ...] [PETSc options]``.

Scene options come from the scene's ``Params`` dataclass (``v_max`` ->
``--v-max``) with the help text in its ``HELP`` dict. Anything of the form
``-petsc_option [value]`` goes to PETSc. Bad input exits with code 2 and a
message naming the parameter, before any meshing, compilation or output.
"""

from __future__ import annotations

import dataclasses
import json
import sys
from contextlib import contextmanager

from mpi4py import MPI

from bcfem.arguments import AxisSpec, build_parser, parse, split_petsc


def main(argv: list[str] | None = None) -> int:
    from bcfem import interrupt
    interrupt.install(MPI.COMM_WORLD)  # first: a signal from here on ends with a status
    try:
        return _main(argv)
    except interrupt.Interrupted as err:  # before the command began
        _say(MPI.COMM_WORLD, f"bcfem: interrupted by {err}")
        return err.exit_code


def _main(argv: list[str] | None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    ours, petsc = split_petsc(argv)
    parser = build_parser()
    args = parse(parser, ours)
    if args.command == "status":
        return _status(args.dir)
    from bcfem.scenes import REGISTRY

    module = REGISTRY[args.scene]
    given = vars(args)  # the flags this command takes (a nested dataclass has none)
    values = {f.name: given[f.name] for f in dataclasses.fields(module.Params) if f.name in given}
    # sweep axes given as --name start:stop:step; the Params hold the default there
    args.ranges = {k: str(v) for k, v in values.items() if isinstance(v, AxisSpec)}
    values = {k: v for k, v in values.items() if k not in args.ranges}
    try:
        params = module.Params(**values)
    except ValueError as err:
        parser.exit(2, f"bcfem {args.command} {args.scene}: error: {err}\n" if MPI.COMM_WORLD.rank == 0 else "")

    from bcfem import interrupt, log
    from bcfem.solver import options
    comm = MPI.COMM_WORLD
    log.configure(comm, quiet=args.quiet)
    options.insert_command_line(petsc)
    command = {"run": _run, "sweep": _sweep, "fit": _fit}[args.command]
    try:
        return command(parser, args, module, params, comm)
    except interrupt.Interrupted as err:
        _say(comm, f"bcfem {args.command} {args.scene}: interrupted by {err}; what was done is in {args.out}")
        return err.exit_code


def _status(out) -> int:
    """``bcfem status DIR``: one line on what the run there did (rank 0; a killed run's summary
    is written)."""
    from bcfem.run import outdir

    comm = MPI.COMM_WORLD
    line, code = outdir.status(out) if comm.rank == 0 else ("", 0)
    code = comm.bcast(code)
    if comm.rank == 0:
        print(line, flush=True)
    return code


def _say(comm, line: str) -> None:
    """One line on stderr, from rank 0."""
    if comm.rank == 0:
        print(line, file=sys.stderr, flush=True)


@contextmanager
def _locked(parser, args, comm):
    """The output directory, created and locked inside; one that is no directory, or that
    another run holds, is bad input (exit 2, before any meshing)."""
    from bcfem.run import outdir
    try:
        created = outdir.lock(args.out, comm, " ".join(sys.argv[1:]))
    except outdir.OutDirError as err:
        parser.exit(2, f"bcfem {args.command} {args.scene}: error: {err}\n" if comm.rank == 0 else "")
    try:
        yield args.out
    finally:
        outdir.unlock(args.out, comm, created)


def _run(parser, args, module, params, comm) -> int:
    import time

    from bcfem import interrupt, jit
    from bcfem.path.checkpoint import ResumeError
    from bcfem.run import resume, runner
    name = f"bcfem run {args.scene}"
    with _locked(parser, args, comm):
        try:  # before any meshing: a checkpoint of another run is bad input
            checkpoints = resume.checkpoints_of(args.out, args.scene, dataclasses.asdict(params), comm,
                                                args.checkpoint_every, args.resume)
        except ResumeError as err:
            parser.exit(2, f"{name}: error: {err}\n" if comm.rank == 0 else "")
        jit.install()
        started = (time.perf_counter(), jit.tally())  # the wall time and compiles count from the build
        try:
            scene = module.build(params, comm)
        except (Exception, interrupt.Interrupted) as err:
            summary = runner.write_unsolved(args.out, args.scene, params, err, comm)
            if isinstance(err, interrupt.Interrupted):
                raise
            _say(comm, f"{name}: {summary['error']} (the traceback is in {args.out / 'summary.json'})")
            return 1
        try:
            summary = runner.solve_into(scene, args.out, comm, plots=args.plots, started=started,
                                        checkpoints=checkpoints)
        except interrupt.Interrupted as err:
            if err.run is None:  # before the solve began: still a status on disk
                runner.write_unsolved(args.out, args.scene, params, err, comm)
            raise
        except runner.SolveError as err:
            internal = "traceback" in err.run.summary
            plain = str(err).startswith("no space left") or "out of memory" in str(err)  # no solver at fault
            _say(comm, f"{name}: {err}; the traceback is in summary.json" if internal else
                 f"{name}: {err}" if plain else f"{name}: solver failed: {err}")
            return 1
    if args.profile and comm.rank == 0:
        print(_profile(summary))
    if comm.rank == 0:
        print(f"wrote in {args.out}: " + ", ".join(summary["files"]))
    return 0


def _profile(summary: dict) -> str:
    """The time split of a run, one line per part, with the counts."""
    wall = summary["wall_time_s"]
    lines = [f"{part:24s} {seconds:8.3f} s {100 * seconds / wall:5.1f} %"
             for part, seconds in summary["time_split_s"].items()]
    compiled = summary["jit"]
    lines.append(f"forms compiled {compiled['compiled']} ({compiled['compile_s']:.3f} s), "
                 f"loaded from the cache {compiled['loaded']} ({compiled['load_s']:.3f} s)")
    lines.append("peak memory per rank " + ", ".join(f"{mb:.0f}" for mb in summary["peak_rss_mb"]) + " MB")
    return "\n".join([f"wall time {wall:.3f} s on {summary['ranks']} rank(s), {summary['dofs']} dofs, "
                      f"{summary['steps']} steps, {summary['newton_iterations']} Newton iterations, "
                      f"{summary['failed_solves']} failed solves", *lines])


def _sweep(parser, args, module, params, comm) -> int:
    from bcfem.run import sweep
    from bcfem.scenes import STUDIES

    studies = STUDIES[args.scene]
    try:
        axes = [sweep.parse_axis(text) for text in args.grid]
        axes += [(name, sweep.parse_range(name, spec)) for name, spec in args.ranges.items()]
        if not axes:
            raise ValueError("no grid axis: give --grid NAME=... or a parameter as START:STOP:STEP")
        points = sweep.grid_points(params, axes)
    except ValueError as err:
        parser.exit(2, f"bcfem sweep {args.scene}: error: {err}\n" if comm.rank == 0 else "")
    with _locked(parser, args, comm):
        if comm.rank == 0:
            sweep.clear_claims(args.out)
        rows = sweep.run(points, studies.SWEEP["solve"], args.out, comm, retry_failed=args.retry_failed,
                         checkpoint_every=args.checkpoint_every)
        title = f"{args.scene}: {studies.SWEEP['title']}"
        # one-value axes are constants; an axis of words is a set of curves or maps, not drawn
        varying = [name for name, values in axes if len(values) > 1]
        if any(isinstance(values, list) for _, values in axes):
            varying = []
        plot = {1: "curves.png", 2: "maps.png"}.get(len(varying))
        if len(varying) == 1:
            sweep.curves(rows, varying[0], studies.SWEEP["maps"], title, args.out / plot, comm)
        elif len(varying) == 2:
            x, y = varying
            sweep.contour_maps(rows, x, y, studies.SWEEP["maps"], title, args.out / plot, comm)
    failures = sweep.failures(rows)
    if comm.rank == 0:
        failed = sum(failures.values())
        print(f"wrote {args.out / 'sweep.csv'} ({len(rows)} points, {failed} failed)"
              + (f" and {args.out / plot}" if plot else ""))
    if failures:
        _say(comm, f"bcfem sweep {args.scene}: {sum(failures.values())} of {len(rows)} points failed:\n"
             + "\n".join(f"  {count} x {reason}" for reason, count in failures.items()))
    return 1 if failures else 0


def _fit(parser, args, module, params, comm) -> int:
    import time

    from bcfem import interrupt, io
    from bcfem.scenes import STUDIES

    studies = STUDIES[args.scene]
    targets = {t: getattr(args, f"target_{t}") for t in studies.FIT_TARGETS}
    t0 = time.perf_counter()
    with _locked(parser, args, comm):
        try:
            result = studies.fit(**targets, params=params, comm=comm)
        except ValueError as err:
            parser.exit(2, f"bcfem fit {args.scene}: error: {err}\n" if comm.rank == 0 else "")
        except interrupt.Interrupted as err:
            io.write_json(args.out / "fit.json", {"status": "interrupted", "error": f"interrupted by {err}",
                                                  "targets": targets, "parameters": dataclasses.asdict(params)}, comm)
            raise
        # the parameters the fit solved with (its own edge and cells), else the given ones
        result = {"status": "ok" if result["converged"] else "failed", "targets": targets,
                  "parameters": dataclasses.asdict(params), **result, "wall_time_s": time.perf_counter() - t0}
        io.write_json(args.out / "fit.json", result, comm)
    if comm.rank == 0:
        print(json.dumps({k: result[k] for k in ("alpha", "adhesion", "alpha_uncertainty",
                                                   "adhesion_uncertainty", "converged") if k in result}))
        print(f"wrote {args.out / 'fit.json'}")
    return 0 if result["converged"] else 1


if __name__ == "__main__":
    sys.exit(main())
