"""The site's generated pages: one per scene, from the command line's own parser (so a page and
``bcfem run SCENE --help`` cannot drift), and one per demo and tutorial, from its jupytext
percent source (prose, equations, code) with the figures ``make report`` committed.

``write_pages(docs)`` writes them under ``docs/_generated/`` (not tracked); ``docs/conf.py``
calls it before Sphinx reads the sources.
"""

from __future__ import annotations

import argparse
import json
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
#: a scene's benchmark page, where it is not named after the scene
BENCHMARK = {"crater": "crater-air"}
GENERATED = "_generated"
#: characters Markdown would read as markup in a help text
_MARKUP = re.compile(r"([\\`*_\[\]<>|{}#])")


def escape(text: str) -> str:
    """``text`` as literal Markdown (one line)."""
    return _MARKUP.sub(r"\\\1", " ".join(text.split()))


def unescape(text: str) -> str:
    return re.sub(r"\\(.)", r"\1", text)


def scene_parsers() -> dict[str, argparse.ArgumentParser]:
    """``bcfem run SCENE``'s parser of every scene."""
    from bcfem.arguments import build_parser

    def choices(parser):
        return next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction)).choices

    return dict(choices(choices(build_parser())["run"]))


def parameter_rows(parser: argparse.ArgumentParser) -> list[tuple[str, str]]:
    """(flags, help) of every option of a scene's parser, as ``--help`` prints them (but -h)."""
    return [(", ".join(a.option_strings), " ".join((a.help or "").split()))
            for a in parser._actions if a.option_strings and a.dest != "help"]


def scene_page(name: str, parser: argparse.ArgumentParser) -> str:
    from mpi4py import MPI

    from bcfem.scenes import REGISTRY

    module = REGISTRY[name]
    package = module.__name__
    stages = getattr(module.build(module.Params(), MPI.COMM_SELF), "stages", ())
    summary = escape(module.SUMMARY)
    lines = [f"# `{name}`", "", f"{summary[0].upper()}{summary[1:]}.", "",
             f"`bcfem run {name} --help` prints this page's model, parameters and columns; "
             f"the scene's code is {{py:mod}}`{package}`.", "",
             "## The model", "", "```text", module.DESCRIPTION, "```", "",
             "## Its energy", "", "```{eval-rst}", f".. automodule:: {model_module(module)}", "   :no-members:",
             "```", "",
             "## Stages", "",
             "With the default parameters the run goes through the stages "
             + ", ".join(f"`{s}`" for s in stages)
             + " (`summary.json`'s `stages` records each one's end; PETSc prefix `bcfem_"
             + name.replace("-", "_") + "_<stage>_`).", "",
             "## Parameters", "",
             "Units in brackets; the range a value must lie in (bad input exits 2 before meshing).", "",
             "| flag | meaning, unit, range (default) |", "|---|---|"]
    lines += [f"| `{flags}` | {escape(text)} |" for flags, text in parameter_rows(parser)]
    lines += ["", "## Outputs", "",
              "`summary.json`, `branch.csv` (one row per accepted state, on disk as it is accepted), "
              "`fields.bp` (VTX) and the scene's PNGs, as every run writes them (the README's "
              "*What a run writes*). The columns of `branch.csv`:", "",
              "| column | unit | meaning |", "|---|---|---|"]
    lines += [f"| `{c.name}` | {escape(c.unit)} | {escape(c.meaning)} |" for c in module.COLUMNS]
    slug = BENCHMARK.get(name, name)
    plot = ROOT / "docs" / "benchmarks" / f"{slug}.png"
    if plot.exists():
        lines += ["", "## Error against run time", "",
                  f"From `make bench` ([the benchmark's page](../../benchmarks/{slug}.md)):", "",
                  f"![{name}: error against wall time](../../benchmarks/{slug}.png)"]
    return "\n".join(lines) + "\n"


def model_module(module) -> str:
    """The module whose docstring states a scene's energy: its package's ``model``, else its own."""
    paths = getattr(module, "__path__", [])
    return f"{module.__name__}.model" if paths and (Path(paths[0]) / "model.py").exists() else module.__name__


def figures_of(stem: str) -> list[Path]:
    """The PNGs ``make report`` committed for demo ``stem`` (its own run and, for the crater
    demos, the run on the dissertation's FE model)."""
    found = []
    for folder in (stem, f"{stem}_dissertation"):
        found += sorted((ROOT / "docs" / "figures" / folder).glob("*.png"))
    return found


def notebook_page(source: Path) -> str:
    """A demo's or tutorial's page: its markdown cells as prose, its code cells as code, then its
    committed figures. In the prose, ``{{ a.b.c:fmt }}`` is the value at a.b.c of the demo's
    ``summary.json`` (``docs/figures/<demo>/``), formatted by ``fmt`` (default ``.4g``), so that a
    quoted number is the computed one; `bcfem.Name` (or `Name`) of a public name links to the
    API reference."""
    import jupytext

    notebook = jupytext.read(source)
    summary_file = ROOT / "docs" / "figures" / source.stem / "summary.json"
    summary = json.loads(summary_file.read_text()) if summary_file.exists() else {}
    parts = []
    for cell in notebook.cells:
        text = cell.source.strip("\n")
        if not text:
            continue
        if cell.cell_type == "markdown":
            text = _QUOTED.sub(lambda m: _quoted(summary, m.group(1), m.group(2), source), text)
            parts.append(_API_NAME.sub(_api_link, text))
        else:
            parts.append(f"```python\n{text}\n```")
    relative = source.relative_to(ROOT)
    if source.parent.name == "demos":  # a tutorial says how to run it
        parts.append(f"Run it: `python {relative}` (`--help` lists its flags; it also runs under `mpirun -n 2`).")
    shown = figures_of(source.stem)
    if shown:
        parts.append("## Figures\n\nAs `make report` draws them (`docs/figures/`):")
        parts += [f"![{png.stem}](../../figures/{png.parent.name}/{png.name})" for png in shown]
    return "\n\n".join(parts) + "\n"


_QUOTED = re.compile(r"\{\{\s*([\w.\-]+)(?::([^}\s]+))?\s*\}\}")
_API_NAME = re.compile(r"`(?:bcfem\.)?([A-Z]\w+)`")


def _quoted(summary: dict, path: str, spec: str | None, source: Path) -> str:
    value = summary
    for key in path.split("."):
        if not isinstance(value, dict) or key not in value:
            raise KeyError(f"{source.name}: the prose quotes {path!r}, which docs/figures/{source.stem}/"
                           f"summary.json lacks (make report writes it)")
        value = value[key]
    return format(value, spec or (".4g" if isinstance(value, float) else ""))


def _api_link(match: re.Match) -> str:
    import bcfem

    name = match.group(1)
    return f"{{py:obj}}`bcfem.{name}`" if name in bcfem.__all__ else match.group(0)


def write_pages(docs: Path) -> None:
    """Write every generated page, and remove those of scenes, demos or tutorials that are gone."""
    out = docs / GENERATED
    pages = {out / "scenes" / f"{name}.md": scene_page(name, parser) for name, parser in scene_parsers().items()}
    for kind in ("demos", "tutorials"):
        pages |= {out / kind / f"{s.stem}.md": notebook_page(s) for s in sorted((ROOT / kind).glob("[!_]*.py"))}
    for stale in set(out.glob("*/*.md")) - set(pages):
        stale.unlink()
    for path, text in pages.items():
        _write(path, text)


def _write(path: Path, text: str) -> None:
    """Write only a change, so that Sphinx rebuilds only what changed."""
    path.parent.mkdir(parents=True, exist_ok=True)
    if not path.exists() or path.read_text() != text:
        path.write_text(text)
