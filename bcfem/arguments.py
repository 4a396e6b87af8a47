"""The command line's parser: one flag per field of a scene's ``Params``, the sweep axes and
the fit targets, and the split of PETSc options from bcfem's own (no dolfinx here)."""

from __future__ import annotations

import argparse
import dataclasses
import functools
import math
import textwrap
from pathlib import Path

from mpi4py import MPI

from bcfem.columns import help_text
from bcfem.params import Bound, bound_of, flag


class _Parser(argparse.ArgumentParser):
    """An ArgumentParser that reports on rank 0 only, and an error in one line naming the flag
    as typed (flags are never abbreviated), exit code 2."""

    def __init__(self, *args, **kwargs):
        kwargs["allow_abbrev"] = False
        super().__init__(*args, **kwargs)

    def _print_message(self, message, file=None):
        if MPI.COMM_WORLD.rank == 0:
            super()._print_message(message, file)

    def error(self, message):
        message = message.replace("argument ", "", 1) if message.startswith("argument ") else message
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def _float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number (got {text!r})") from None
    if math.isnan(value):
        raise argparse.ArgumentTypeError("nan is not a number here")
    return value


def _integer(text: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number (got {text!r})") from None


def _bounded(bound: Bound):
    """A float flag checked against ``bound`` as it is parsed (a fit's targets)."""
    def parse(text: str) -> float:
        value = _float(text)
        if not bound.admits(value):
            raise argparse.ArgumentTypeError(f"must be {bound} (got {text})")
        return value

    return parse


def _reported(convert):
    """A parser whose ``ValueError`` argparse reports with its message (one line, exit 2)."""
    def parse(text: str):
        try:
            return convert(text)
        except ValueError as err:
            raise argparse.ArgumentTypeError(str(err)) from None

    parse.__name__ = convert.__name__
    return parse


class AxisSpec(str):
    """A sweep flag's ``start:stop:step`` (e.g. ``--preload 0:0.5:0.025``): a grid axis."""


def _range_or(convert):
    def parse(text: str):
        # start:stop:step of numbers (a word before the colon is the field's own, a profile)
        return AxisSpec(text) if ":" in text and _number(text.split(":")[0]) else convert(text)

    parse.__name__ = f"start:stop:step or {convert.__name__}"
    return parse


def _add_params(parser, params_cls, ranges: bool = False) -> None:
    """One flag per field of ``params_cls``; with ``ranges`` a float flag also takes
    ``start:stop:step`` (a sweep axis). A field's help, unit, choices, named values and range
    come from its metadata (``help``, ``unit``, ``choices``, ``words``, ``bound``:
    :func:`bcfem.params.describe`)."""
    defaults = params_cls()
    for f in dataclasses.fields(params_cls):
        default = getattr(defaults, f.name)
        if dataclasses.is_dataclass(default):
            continue
        kind = type(default)
        text = f.metadata.get("help", "")
        unit = f.metadata.get("unit", "")
        unit = f" [{unit}]" if unit not in ("", "1") else ""
        bound = bound_of(params_cls, f.name)
        within = f"; {bound}" if bound else ""
        kwargs = {"default": default, "help": f"{text}{unit}{within} (default: {default})"}
        choices = f.metadata.get("choices")
        if choices:
            kwargs["choices"] = list(choices)
        if kind is bool:
            kwargs["action"] = argparse.BooleanOptionalAction
        elif "parse" in f.metadata:  # a text the field's own parser reads (a number or a profile)
            kwargs["type"] = _reported(f.metadata["parse"])
        else:
            kwargs["type"] = {float: _float, int: _integer}.get(kind, kind)
        words = f.metadata.get("words")
        if words:  # named values, e.g. --preload closure
            kwargs["type"] = _words_or(words, kwargs["type"])
        if ranges and kind is float:
            kwargs["type"] = _range_or(kwargs["type"])
        parser.add_argument(flag(f.name), dest=f.name, **kwargs)


def compiling(params_cls) -> str:
    """What a new value of each kind of parameter costs the form compiler, for ``--help``."""
    defaults = params_cls()
    chosen = [flag(f.name) for f in dataclasses.fields(params_cls)
              if not dataclasses.is_dataclass(getattr(defaults, f.name))
              and (f.metadata.get("choices")
                   or type(getattr(defaults, f.name)) in (bool, int, str))]
    text = ("Compiling: every number reaches the forms as a constant, so a new value compiles no form "
            "(a number that is 0 may leave its term out, another form). These select the forms, the "
            "elements or the mesh, and a new value may compile forms once (FFCx's cache keeps them): "
            + (", ".join(chosen) or "none") + ".")
    return textwrap.fill(text, 80, break_on_hyphens=False)


def _words_or(words: dict, convert):
    def parse(text: str):
        return words[text] if text in words else convert(text)

    parse.__name__ = f"{' or '.join(words)} or {convert.__name__}"
    return parse


def _seconds(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number of seconds") from None
    if not value >= 0 or value == float("inf"):
        raise argparse.ArgumentTypeError(f"{text!r}: give a finite number of seconds >= 0")
    return value


@functools.cache  # one parser per process: building it takes 50 ms
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
                              epilog=f"{help_text(module.COLUMNS)}\n\n{compiling(module.Params)}",
                              formatter_class=argparse.RawDescriptionHelpFormatter)
        _add_params(p, module.Params)
        p.add_argument("--out", type=Path, default=Path("results") / name, help="results directory")
        p.add_argument("--quiet", action="store_true", help="no progress line")
        p.add_argument("--plots", action=argparse.BooleanOptionalAction, default=True,
                       help="draw the PNGs (matplotlib is loaded only to draw them)")
        p.add_argument("--profile", action="store_true",
                       help="print where the wall time went (also in summary.json: time_split_s)")
        p.add_argument("--resume", action="store_true",
                       help="continue the killed, interrupted or failed run in --out from its last checkpoint "
                            "(on any number of ranks; the same parameters); from the start if it has none")
        p.add_argument("--checkpoint-every", type=_seconds, default=60.0, metavar="SECONDS",
                       help="write a checkpoint at a load path's fixed steps at most this often, in seconds "
                            ">= 0 (0: at every one; default 60); a run that ends ok removes them")
    status = sub.add_parser("status", help="what the run in a results directory did: finished, failed, "
                            "interrupted, killed (its rows kept), or running")
    status.add_argument("dir", type=Path, help="the run's --out directory")
    from bcfem.scenes import STUDIES

    sweep = sub.add_parser("sweep", help="solve a grid of parameter points over MPI ranks (resumable)")
    sweeps = sweep.add_subparsers(dest="scene", required=True, metavar="SCENE", parser_class=_Parser)
    fit = sub.add_parser("fit", help="recover parameters from measured quantities")
    fits = fit.add_subparsers(dest="scene", required=True, metavar="SCENE", parser_class=_Parser)
    for name, studies in STUDIES.items():
        module = REGISTRY[name]
        p = sweeps.add_parser(name, help=f"maps {studies.SWEEP['title']}", description=module.DESCRIPTION,
                              formatter_class=argparse.RawDescriptionHelpFormatter)
        _add_params(p, module.Params, ranges=True)
        p.add_argument("--grid", action="append", default=[], metavar="NAME=START:STOP:COUNT",
                       help="a grid axis: NAME=START:STOP:COUNT or NAME=V1,V2,... (repeat for each axis; "
                            "two axes give contour maps); a parameter flag given as START:STOP:STEP "
                            "(e.g. --preload 0:0.5:0.025) is an axis too")
        p.add_argument("--out", type=Path, default=Path("results") / f"{name}-sweep")
        p.add_argument("--quiet", action="store_true")
        p.add_argument("--retry-failed", action="store_true",
                       help="solve again the points a previous run recorded as failed (else they are kept)")
        p.add_argument("--checkpoint-every", type=_seconds, default=60.0, metavar="SECONDS",
                       help="write a checkpoint of the point being solved at most this often, in seconds >= 0 "
                            "(default 60); a rerun goes on from a killed point's last one")
        if not studies.FIT_TARGETS:  # no inverse problem for this scene
            continue
        p = fits.add_parser(name, help="inverse parameter extraction", description=module.DESCRIPTION,
                            formatter_class=argparse.RawDescriptionHelpFormatter)
        _add_params(p, module.Params)
        for target, (text, bound) in studies.FIT_TARGETS.items():
            p.add_argument(f"--{target}", dest=f"target_{target}", type=_bounded(bound), required=True,
                           help=f"{text}; {bound}")
        p.add_argument("--out", type=Path, default=Path("results") / f"{name}-fit")
        p.add_argument("--quiet", action="store_true")
    return parser


def _negative_values_attached(argv: list[str]) -> list[str]:
    """``--adhesion -1e4`` as ``--adhesion=-1e4``: argparse takes only ``-1`` and ``-.5`` for
    negative numbers, and ``-1e4`` or ``-inf`` for a flag."""
    out: list[str] = []
    for token in argv:
        if out and out[-1].startswith("--") and "=" not in out[-1] and token.startswith("-") and _number(token):
            out[-1] = f"{out[-1]}={token}"
        else:
            out.append(token)
    return out


def parse(parser, argv: list[str]) -> argparse.Namespace:
    """``parser.parse_args(argv)``, but an unknown flag is reported by its scene's parser, in one
    line, with the nearest flag of that scene (``--size_contact``: did you mean --size-contact?)."""
    import difflib

    args, unknown = parser.parse_known_args(_negative_values_attached(argv))
    if unknown:
        scene = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
        scene = scene.choices[args.command]
        scene = next(a for a in scene._actions if isinstance(a, argparse._SubParsersAction)).choices[args.scene]
        flags = [o for a in scene._actions for o in a.option_strings]
        near = difflib.get_close_matches(unknown[0].replace("_", "-"), flags, n=1)
        scene.error(f"unrecognized argument {unknown[0]}" + (f": did you mean {near[0]}?" if near else ""))
    return args


def _number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def split_petsc(argv: list[str]) -> tuple[list[str], list[str]]:
    """Separate ``-key [value]`` PETSc options from bcfem's ``--options``."""
    ours, petsc = [], []
    i = 0
    while i < len(argv):
        a = argv[i]
        if a.startswith("-") and not a.startswith("--") and len(a) > 2 and a[1].isalpha() and not _number(a):
            petsc.append(a)
            if i + 1 < len(argv) and not argv[i + 1].startswith("-"):
                petsc.append(argv[i + 1])
                i += 1
        else:
            ours.append(a)
        i += 1
    return ours, petsc
