"""What every demo script shares: its command line, logging and a rank-0 report."""

from __future__ import annotations

import argparse
from pathlib import Path

from bcfem.log import configure


def setup(name: str, description: str, comm):
    """Parse ``--out`` (default ``results/<name>``) and ``--quiet``; configure logging.

    Returns:
        (args, report): the parsed arguments and a function that prints on rank 0.
    """
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--out", type=Path, default=Path("results") / name,
                        help=f"output directory (default: results/{name})")
    parser.add_argument("--quiet", action="store_true", help="no continuation progress lines")
    args, _ = parser.parse_known_args()  # tolerate a notebook kernel's own arguments
    configure(comm, quiet=args.quiet)

    def report(message: str) -> None:
        if comm.rank == 0:
            print(message, flush=True)

    return args, report
