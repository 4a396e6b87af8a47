"""The README's research-script example runs as printed."""

import re
from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"


def example(name: str) -> str:
    text = README.read_text()
    match = re.search(rf"<!-- readme-example: {name} -->\s*```python\n(.*?)```", text, re.S)
    assert match, f"README example {name!r} not found"
    return match.group(1)


def test_gravity_example_runs():
    code = example("gravity")
    assert "LiquidGravity" in code and "assert" in code
    exec(compile(code, "README.md:gravity", "exec"), {"__name__": "readme_example"})
