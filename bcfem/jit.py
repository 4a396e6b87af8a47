"""The form compiler, measured: how many forms FFCx compiled and loaded, and how long each took.

dolfinx compiles a form the first time its signature is seen (the signature depends on the
form's structure, never on a ``fem.Constant``'s value) and loads it from the cache after
that. :func:`install` wraps FFCx's two entry points once per process; :func:`tally` reads the
running totals, so that a run, a sweep or a test reports what it paid the JIT
(``summary.json``'s ``jit``, ``--profile``'s ``jit`` line).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, fields
from time import perf_counter


@dataclass(frozen=True)
class Tally:
    """Compiler work in this process.

    Attributes:
        compiled: forms and expressions compiled (cache misses).
        compile_s: seconds spent compiling them (code generation and the C compiler).
        loaded: forms and expressions loaded from the cache.
        load_s: seconds spent loading them.
    """

    compiled: int = 0
    compile_s: float = 0.0
    loaded: int = 0
    load_s: float = 0.0

    def __sub__(self, other: Tally) -> Tally:
        return Tally(*(getattr(self, f.name) - getattr(other, f.name) for f in fields(self)))

    @property
    def seconds(self) -> float:
        """Compile and load time."""
        return self.compile_s + self.load_s

    def over(self, comm) -> dict:
        """The largest of each count over ``comm``'s ranks (rank 0 compiles, the others load
        what it wrote), as ``summary.json`` reports it (collective)."""
        from mpi4py import MPI
        return {f.name: comm.allreduce(getattr(self, f.name), op=MPI.MAX) for f in fields(self)}


_total = Tally()
_installed = False


def install() -> None:
    """Count every form and expression FFCx compiles or loads from here on (once per process)."""
    global _installed
    if _installed:
        return
    _installed = True
    import ffcx.codegeneration.jit as ffcx_jit

    for name in ("compile_forms", "compile_expressions"):
        setattr(ffcx_jit, name, _metered(getattr(ffcx_jit, name)))


def _metered(compile_objects):
    @functools.wraps(compile_objects)
    def metered(objects, *args, **kwargs):
        global _total
        t0 = perf_counter()
        result = compile_objects(objects, *args, **kwargs)
        seconds = perf_counter() - t0
        # FFCx returns the generated code only when it compiled (a cache hit: (None, None))
        if result[2][0] is not None:
            _total = Tally(_total.compiled + len(objects), _total.compile_s + seconds, _total.loaded, _total.load_s)
        else:
            _total = Tally(_total.compiled, _total.compile_s, _total.loaded + len(objects), _total.load_s + seconds)
        return result

    return metered


class Clock:
    """Wall time since its creation less the form compiler's, for a timing that must not count
    a compile (a stability check's first call compiles its forms)."""

    def __init__(self):
        self._start, self._compiling = perf_counter(), _total.seconds

    def seconds(self) -> float:
        return perf_counter() - self._start - (_total.seconds - self._compiling)


def tally() -> Tally:
    """The totals so far (zero before :func:`install`)."""
    return _total
