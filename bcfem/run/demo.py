"""What every demo script shares: its command line, logging, a rank-0 report and the run
context its figures receive."""

from __future__ import annotations

import argparse
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from bcfem.log import configure

#: the flags every demo takes (``full``/``refine``/``dissertation`` say what they change in the
#: demo's --help)
FLAGS = ("--out", "--quiet", "--full", "--refine", "--dissertation-model")


def parser(name: str, description: str, full: str, refine: str,
           dissertation: str = "the demo's model is the dissertation's") -> argparse.ArgumentParser:
    """The demo's command line: ``--out``, ``--quiet``, ``--full`` (the dissertation's published
    grid), ``--refine`` (a finer mesh) and ``--dissertation-model`` (the dissertation's FE model
    where the demo's default is the experiment's); ``full``, ``refine`` and ``dissertation`` are
    their help texts."""
    p = argparse.ArgumentParser(description=description)
    p.add_argument("--out", type=Path, default=Path("results") / name,
                   help=f"output directory (default: results/{name})")
    p.add_argument("--quiet", action="store_true", help="no continuation progress lines")
    p.add_argument("--full", action="store_true", help=f"the published grid: {full}")
    p.add_argument("--refine", action="store_true", help=f"a finer mesh: {refine}")
    p.add_argument("--dissertation-model", action="store_true",
                   help=f"the dissertation's FE model: {dissertation}")
    return p


def setup(name: str, description: str, comm, full: str = "the demo's grid is the published one",
          refine: str = "the demo's mesh is fixed", dissertation: str = "the demo's model is the dissertation's"):
    """Parse the demo's command line (:func:`parser`) and configure logging.

    Returns:
        (args, report): the parsed arguments (``out``, ``quiet``, ``full``, ``refine``,
        ``dissertation_model``) and a function that prints on rank 0.
    """
    args, _ = parser(name, description, full, refine, dissertation).parse_known_args()  # a kernel's own arguments
    configure(comm, quiet=args.quiet)

    def report(message: str) -> None:
        if comm.rank == 0:
            print(message, flush=True)

    return args, report


@dataclass(frozen=True)
class Run:
    """The context of one demo run that its figures need: the parsed arguments of :func:`setup`,
    the communicator the results are written on and the rank-0 ``report``.

    A demo's results object carries one ``Run``, so that its ``draw(results)`` takes one argument.
    """

    args: argparse.Namespace
    comm: Any  # mpi4py.MPI.Comm (not imported here, so that --help stays fast)
    report: Callable[[str], None]

    @property
    def out(self) -> Path:
        """The output directory (``--out``)."""
        return self.args.out
