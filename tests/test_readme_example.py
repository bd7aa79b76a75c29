"""The README's examples run as written and print what they say they print; the first one is
the same code as on the site's Getting started page."""

from __future__ import annotations

import contextlib
import io
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _blocks(path: Path, heading: str) -> list[str]:
    """The ```python blocks under the markdown heading ``heading`` (up to the next one)."""
    text = path.read_text(encoding="utf-8")
    m = re.search(rf"^#+ {re.escape(heading)}\n(.*?)(?=^#+ |\Z)", text, flags=re.M | re.S)
    assert m, f"{path.name} has no section {heading!r}"
    return re.findall(r"```python\n(.*?)```", m.group(1), flags=re.S)


def _run(code: str) -> str:
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(code, "<README example>", "exec"), {"__name__": "__readme__"})
    return out.getvalue()


def test_readme_api_example_runs_and_prints_what_it_says():
    blocks = _blocks(ROOT / "README.md", "Example")
    assert len(blocks) == 2
    code = blocks[0]
    assert 8 <= len(code.strip().splitlines()) <= 16
    said = re.search(r"# prints: (.*)$", code, flags=re.M)
    assert said, "the example says what it prints"
    assert _run(code).strip() == said.group(1).strip()


def test_readme_env_example_runs():
    code = _blocks(ROOT / "README.md", "Example")[1]
    out = _run(code).split()
    assert len(out) == 2 and out[0] in ("G", "H") and out[1] in ("G", "H")


def test_getting_started_shows_the_same_first_query():
    readme = _blocks(ROOT / "README.md", "Example")[0]
    site = _blocks(ROOT / "docs" / "getting-started.md", "First query")[0]
    assert site == readme


def test_readme_is_a_front_page():
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    assert len(text.splitlines()) <= 300
    assert "python -m pytest -q -n 2" in text
    for word in ("issue ", "this round", "previous round", "Re-run after"):
        assert word.lower() not in text.lower(), f"README carries history: {word!r}"
