"""The package's rooms form layers: a module imports only from its own room or from rooms
below it, so there is no import circle. Read from the source (no import is run)."""

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "bcfem"
#: lowest first; a room may import from its own rank and below
LAYERS = ["base", "kinematics", "physics", "contact solver geometry theory", "stability", "path", "run",
          "scenes", "face"]
RANK = {room: i for i, rooms in enumerate(LAYERS) for room in rooms.split()}
FACE = {"cli", "arguments", "__main__", "__init__"}


def room(module: str) -> str:
    parts = module.split(".")[1:]
    if len(parts) <= 1:
        return "face" if not parts or parts[0] in FACE else "base"
    return parts[0]


def modules() -> dict[str, Path]:
    found = {}
    for path in PACKAGE.rglob("*.py"):
        parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
        found[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return found


def imports(path: Path, known: dict) -> set[str]:
    """The bcfem modules ``path`` imports (at any depth, type-only imports included)."""
    out = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("bcfem"):
            for alias in node.names:
                full = f"{node.module}.{alias.name}"
                out.add(full if full in known else node.module)
        elif isinstance(node, ast.Import):
            out.update(a.name for a in node.names if a.name in known)
    return out - {"bcfem"}


def test_no_room_imports_from_a_room_above_it():
    known = modules()
    upward = [(m, n) for m, path in known.items() for n in imports(path, known)
              if RANK[room(n)] > RANK[room(m)]]
    assert not upward, f"imports from a higher layer: {upward}"


def test_there_is_no_import_circle():
    known = modules()
    graph = {m: imports(p, known) & set(known) for m, p in known.items()}
    state: dict[str, int] = {}

    def visit(m, trail):
        state[m] = 1
        for n in graph[m]:
            if state.get(n) == 1:
                pytest.fail(f"import circle: {' -> '.join(trail[trail.index(n):] + [n])}")
            if not state.get(n):
                visit(n, trail + [n])
        state[m] = 2

    for m in graph:
        if not state.get(m):
            visit(m, [m])


def test_the_package_top_holds_about_a_dozen_modules():
    top = sorted(p.stem for p in PACKAGE.glob("*.py"))
    assert len(top) <= 13, top


def test_the_readme_map_names_every_module_of_the_rooms():
    """The README's architecture map is drawn from the folders: every module of bcfem's top
    and of its rooms is named in it (scene packages list their own modules)."""
    readme = (PACKAGE.parent / "README.md").read_text()
    block = readme.split("## Architecture", 1)[1].split("```")[1]
    words = set(block.replace("/", " ").replace(",", " ").replace("(", " ").replace(")", " ").split())
    rooms = {"kinematics", "physics", "contact", "solver", "stability", "path", "run"}
    modules = [p for p in PACKAGE.glob("*.py")] + [p for room in rooms for p in (PACKAGE / room).glob("*.py")]
    missing = sorted(p.stem for p in modules if p.stem not in words and p.stem not in ("__init__", "__main__"))
    assert not missing, f"modules the README's map does not name: {missing}"
