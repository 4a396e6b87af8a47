"""Command line: ``bcfem run|sweep|fit SCENE [--param value ...] [PETSc options]``.

Scene options come from the scene's ``Params`` dataclass (``v_max`` ->
``--v-max``) with the help text in its ``HELP`` dict. Anything of the form
``-petsc_option [value]`` goes to PETSc. Bad input exits with code 2 and a
message naming the parameter, before any meshing, compilation or output.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import sys
from pathlib import Path

from mpi4py import MPI


class _Parser(argparse.ArgumentParser):
    """An ArgumentParser that reports errors on rank 0 only."""

    def _print_message(self, message, file=None):
        if MPI.COMM_WORLD.rank == 0:
            super()._print_message(message, file)


def _float(text: str) -> float:
    value = float(text)
    if math.isnan(value):
        raise argparse.ArgumentTypeError("nan is not a number here")
    return value


class _Range(str):
    """A sweep flag's ``start:stop:step`` (e.g. ``--preload 0:0.5:0.025``): a grid axis."""


def _range_or(convert):
    def parse(text: str):
        return _Range(text) if ":" in text else convert(text)

    parse.__name__ = f"start:stop:step or {convert.__name__}"
    return parse


def _add_params(parser, params_cls, help_text: dict, ranges: bool = False) -> None:
    """One flag per field of ``params_cls``; with ``ranges`` a float flag also takes
    ``start:stop:step`` (a sweep axis). A field's help, unit, choices and named values
    come from its metadata (``help``, ``unit``, ``choices``, ``words``), else from
    ``help_text`` and the class's ``CHOICES`` and ``WORDS``."""
    defaults = params_cls()
    for f in dataclasses.fields(params_cls):
        default = getattr(defaults, f.name)
        if dataclasses.is_dataclass(default):
            continue
        flag = "--" + f.name.replace("_", "-")
        kind = type(default)
        text = f.metadata.get("help", help_text.get(f.name, ""))
        unit = f.metadata.get("unit", "")
        unit = f" [{unit}]" if unit not in ("", "1") else ""
        kwargs = {"default": default, "help": f"{text}{unit} (default: {default})"}
        choices = f.metadata.get("choices", getattr(params_cls, "CHOICES", {}).get(f.name))
        if choices:
            kwargs["choices"] = list(choices)
        if kind is bool:
            kwargs["action"] = argparse.BooleanOptionalAction
        else:
            kwargs["type"] = _float if kind is float else kind
        words = f.metadata.get("words", getattr(params_cls, "WORDS", {}).get(f.name))
        if words:  # named values, e.g. --preload closure
            kwargs["type"] = _words_or(words, kwargs["type"])
        if ranges and kind is float:
            kwargs["type"] = _range_or(kwargs["type"])
        parser.add_argument(flag, dest=f.name, **kwargs)


def _words_or(words: dict, convert):
    def parse(text: str):
        return words[text] if text in words else convert(text)

    parse.__name__ = f"{' or '.join(words)} or {convert.__name__}"
    return parse


def build_parser():
    from bcfem.scenes import REGISTRY

    parser = _Parser(prog="bcfem", description="Blisters and craters: fluid-induced large deformation "
                     "at soft interfaces (FEniCSx). PETSc options (-snes_rtol 1e-12, ...) pass through; "
                     "the user's values win over bcfem's defaults.")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    run = sub.add_parser("run", help="trace one scene along its load path",
                         description="Scenes: " + ", ".join(REGISTRY))
    scenes = run.add_subparsers(dest="scene", required=True, metavar="SCENE", parser_class=_Parser)
    for name, module in REGISTRY.items():
        p = scenes.add_parser(name, help=module.SUMMARY, description=module.DESCRIPTION,
                              formatter_class=argparse.RawDescriptionHelpFormatter)
        _add_params(p, module.Params, getattr(module, "HELP", {}))
        p.add_argument("--out", type=Path, default=Path("results") / name, help="results directory")
        p.add_argument("--quiet", action="store_true", help="no progress line")
        p.add_argument("--plots", action=argparse.BooleanOptionalAction, default=True,
                       help="draw the PNGs (matplotlib is loaded only to draw them)")
        p.add_argument("--profile", action="store_true",
                       help="print where the wall time went (also in summary.json: time_split_s)")
    from bcfem.scenes import STUDIES

    sweep = sub.add_parser("sweep", help="solve a grid of parameter points over MPI ranks (resumable)")
    sweeps = sweep.add_subparsers(dest="scene", required=True, metavar="SCENE", parser_class=_Parser)
    fit = sub.add_parser("fit", help="recover parameters from measured quantities")
    fits = fit.add_subparsers(dest="scene", required=True, metavar="SCENE", parser_class=_Parser)
    for name, studies in STUDIES.items():
        module = REGISTRY[name]
        p = sweeps.add_parser(name, help=f"maps {studies.SWEEP['title']}", description=module.DESCRIPTION,
                              formatter_class=argparse.RawDescriptionHelpFormatter)
        _add_params(p, module.Params, getattr(module, "HELP", {}), ranges=True)
        p.add_argument("--grid", action="append", default=[], metavar="NAME=START:STOP:COUNT",
                       help="a grid axis: NAME=START:STOP:COUNT or NAME=V1,V2,... (repeat for each axis; "
                            "two axes give contour maps); a parameter flag given as START:STOP:STEP "
                            "(e.g. --preload 0:0.5:0.025) is an axis too")
        p.add_argument("--out", type=Path, default=Path("results") / f"{name}-sweep")
        p.add_argument("--quiet", action="store_true")
        p.add_argument("--retry-failed", action="store_true",
                       help="solve again the points a previous run recorded as failed (else they are kept)")
        if not hasattr(studies, "fit"):
            continue
        p = fits.add_parser(name, help="inverse parameter extraction", description=module.DESCRIPTION,
                            formatter_class=argparse.RawDescriptionHelpFormatter)
        _add_params(p, module.Params, getattr(module, "HELP", {}))
        for target, text in studies.FIT_TARGETS.items():
            p.add_argument(f"--{target}", dest=f"target_{target}", type=_float, required=True, help=text)
        p.add_argument("--out", type=Path, default=Path("results") / f"{name}-fit")
        p.add_argument("--quiet", action="store_true")
    return parser


def _split_petsc(argv: list[str]) -> tuple[list[str], list[str]]:
    """Separate ``-key [value]`` PETSc options from bcfem's ``--options``."""
    ours, petsc = [], []
    i = 0
    while i < len(argv):
        a = argv[i]
        if a.startswith("-") and not a.startswith("--") and len(a) > 2 and a[1].isalpha():
            petsc.append(a)
            if i + 1 < len(argv) and not argv[i + 1].startswith("-"):
                petsc.append(argv[i + 1])
                i += 1
        else:
            ours.append(a)
        i += 1
    return ours, petsc


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    ours, petsc = _split_petsc(argv)
    parser = build_parser()
    args = parser.parse_args(ours)
    from bcfem.scenes import REGISTRY

    module = REGISTRY[args.scene]
    values = {f.name: getattr(args, f.name) for f in dataclasses.fields(module.Params)
              if hasattr(args, f.name)}
    # sweep axes given as --name start:stop:step; the Params hold the default there
    args.ranges = {k: str(v) for k, v in values.items() if isinstance(v, _Range)}
    values = {k: v for k, v in values.items() if k not in args.ranges}
    try:
        params = module.Params(**values)
    except ValueError as err:
        parser.exit(2, f"bcfem {args.command} {args.scene}: error: {err}\n" if MPI.COMM_WORLD.rank == 0 else "")

    from bcfem import log, options, runner

    comm = MPI.COMM_WORLD
    log.configure(comm, quiet=args.quiet)
    options.insert_command_line(petsc)
    if args.command == "sweep":
        return _sweep(parser, args, module, params, comm)
    if args.command == "fit":
        return _fit(parser, args, module, params, comm)
    try:
        summary = runner.run(module.build(params, comm), args.out, comm, plots=args.plots)
    except runner.SolveError as err:
        if comm.rank == 0:
            print(f"bcfem run {args.scene}: solver failed: {err}", file=sys.stderr)
        return 1
    if args.profile and comm.rank == 0:
        print(_profile(summary))
    if comm.rank == 0:
        written = sorted(p.name for p in args.out.iterdir() if not p.name.startswith("."))
        print(f"wrote in {args.out}: " + ", ".join(written))
    return 0


def _profile(summary: dict) -> str:
    """The time split of a run, one line per part, with the counts."""
    wall = summary["wall_time_s"]
    lines = [f"{part:24s} {seconds:8.3f} s {100 * seconds / wall:5.1f} %"
             for part, seconds in summary["time_split_s"].items()]
    return "\n".join([f"wall time {wall:.3f} s on {summary['ranks']} rank(s), {summary['dofs']} dofs, "
                      f"{summary['steps']} steps, {summary['newton_iterations']} Newton iterations, "
                      f"{summary['failed_solves']} failed solves", *lines])


def _sweep(parser, args, module, params, comm) -> int:
    from bcfem import sweep
    from bcfem.log import configure
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
    configure(comm, quiet=args.quiet)
    rows = sweep.run(points, studies.SWEEP["solve"], args.out, comm, retry_failed=args.retry_failed)
    title = f"{args.scene}: {studies.SWEEP['title']}"
    # one-value axes are constants; an axis of words is a set of curves or maps, not drawn
    varying = [name for name, values in axes if len(values) > 1]
    if any(isinstance(values, list) for _, values in axes):
        varying = []
    plot = {1: "curves.png", 2: "maps.png"}.get(len(varying))
    if len(varying) == 1:
        sweep.curves(rows, varying[0], studies.SWEEP["maps"], title, args.out / plot, comm)
    elif len(varying) == 2:
        sweep.contour_maps(rows, *varying, studies.SWEEP["maps"], title, args.out / plot, comm)
    if comm.rank == 0:
        failed = sum(r["status"] != "ok" for r in rows)
        print(f"wrote {args.out / 'sweep.csv'} ({len(rows)} points, {failed} failed)"
              + (f" and {args.out / plot}" if plot else ""))
    return 0


def _fit(parser, args, module, params, comm) -> int:
    import time

    from bcfem import io
    from bcfem.scenes import STUDIES

    studies = STUDIES[args.scene]
    targets = {t: getattr(args, f"target_{t}") for t in studies.FIT_TARGETS}
    t0 = time.perf_counter()
    try:
        result = studies.fit(**targets, params=params, comm=comm)
    except ValueError as err:
        parser.exit(2, f"bcfem fit {args.scene}: error: {err}\n" if comm.rank == 0 else "")
    result = {"targets": targets, "parameters": dataclasses.asdict(params), **result,
              "wall_time_s": time.perf_counter() - t0}
    io.write_json(args.out / "fit.json", result, comm)
    if comm.rank == 0:
        print(json.dumps({k: result[k] for k in ("alpha", "adhesion", "alpha_uncertainty",
                                                   "adhesion_uncertainty", "converged") if k in result}))
        print(f"wrote {args.out / 'fit.json'}")
    return 0 if result["converged"] else 1


if __name__ == "__main__":
    sys.exit(main())
