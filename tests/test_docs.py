"""The site's scene pages against ``bcfem run SCENE --help``: both come from the same parser,
and a page's parameter rows must read as the help's, range and unit included."""

import re
import sys
from pathlib import Path

import pytest
from helpers import bcfem

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "docs" / "_ext"))
import bcfem_pages

SCENES = bcfem_pages.scene_parsers()


def page_rows(page: str) -> dict[str, str]:
    """flag -> text of a scene page's parameter table."""
    rows = re.findall(r"^\| `(--[^`]+)` \| (.*) \|$", page, flags=re.MULTILINE)
    return {flag.split(",")[0]: bcfem_pages.unescape(text) for flag, text in rows}


def help_entries(text: str) -> dict[str, str]:
    """flag -> its help text, from ``--help``'s options section (one flag per entry)."""
    options = text.split("options:", 1)[1].split("\n\n", 1)[0]
    entries: dict[str, str] = {}
    flag = None
    for line in options.splitlines():
        match = re.match(r"^  (--?[\w-]+)(?:, --[\w-]+)?(?: [A-Z_{},.\w-]+)?(?:  +(.*))?$", line)
        if match:
            flag = match.group(1)
            entries[flag] = match.group(2) or ""
        elif flag:
            entries[flag] += " " + line.strip()
    return {f: " ".join(t.split()) for f, t in entries.items()}


def help_text(scene: str) -> str:
    """What ``bcfem run SCENE --help`` prints, unwrapped (argparse's print_help is format_help)."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("COLUMNS", "100000")
        return SCENES[scene].format_help()


def test_the_help_is_the_commands():
    """``bcfem run crater --help`` prints what :func:`help_text` reads."""
    res = bcfem("run", "crater", "--help", env={"COLUMNS": "100000"})
    assert res.returncode == 0, res.stderr
    assert res.stdout == help_text("crater")


@pytest.mark.parametrize("scene", sorted(SCENES))
def test_a_scene_page_states_each_parameter_as_help_does(scene):
    page = bcfem_pages.scene_page(scene, SCENES[scene])
    rows = page_rows(page)
    helped = help_entries(help_text(scene))
    assert set(rows) == set(helped) - {"-h"}, "the page and --help list other flags"
    for flag, text in rows.items():
        assert text == helped[flag], f"{scene} {flag}: the page says {text!r}, --help {helped[flag]!r}"
    ranged = [text for text in rows.values() if re.search(r"; in [\[(]", text)]
    assert ranged, "no parameter states a range"


def test_a_demo_page_quotes_the_numbers_its_run_wrote(tmp_path):
    """``{{ path:fmt }}`` in a demo's prose is the value in its summary.json, and a path the
    summary lacks stops the build with the demo's name."""
    import json

    demo = bcfem_pages.ROOT / "demos" / "blister_adhesive.py"
    summary = json.loads((bcfem_pages.ROOT / "docs" / "figures" / "blister_adhesive" / "summary.json").read_text())
    page = bcfem_pages.notebook_page(demo)
    assert "{{" not in page
    onset = summary["dissertation_comparison"]["Vc_neo-hookean"]["ours"]
    assert f"{onset:.3f} (neo-Hookean)" in page
    tutorial = bcfem_pages.notebook_page(bcfem_pages.ROOT / "tutorials" / "add_a_term.py")
    assert "{py:obj}`bcfem.Term`" in tutorial, "a public name in the prose links to the API reference"
    broken = tmp_path / "blister_adhesive.py"
    broken.write_text(demo.read_text().replace("Vc_neo-hookean.ours", "Vc_neo-hookean.missing", 1))
    with pytest.raises(KeyError, match="blister_adhesive.py: the prose quotes"):
        bcfem_pages.notebook_page(broken)
