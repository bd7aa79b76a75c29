"""Every Python snippet in the README, the docs and the docstrings' fenced examples that
makes a sensorplan env names it ``"sensorplan_gym:sensorplan/..."`` (Gymnasium imports the
package, which registers the ids), unless the snippet imports ``sensorplan_gym`` itself: a
snippet pasted into a fresh interpreter must run."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
MAKE = re.compile(r"""\b(?:gym|gymnasium)\.make(?:_vec)?\(\s*["']([^"']+)["']""")


def markdown_files() -> list[Path]:
    files = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
    files += sorted((ROOT / "agents").rglob("*.md"))
    # docstrings with fenced examples (the docs site renders them)
    for pkg in ("geometry", "sensorplan_gym", "agents"):
        files += [f for f in sorted((ROOT / pkg).rglob("*.py")) if "```python" in f.read_text()]
    return [f for f in files if f.is_file()]


def python_snippets(text: str) -> list[str]:
    """The bodies of the fenced ``python`` code blocks of a markdown text (indented fences,
    as in list items, included)."""
    out, cur, fence = [], None, None
    for line in text.splitlines():
        s = line.strip()
        if cur is None and s.startswith("```") and s[3:].strip().lower() in ("python", "py"):
            cur, fence = [], line[: len(line) - len(line.lstrip())]
        elif cur is not None and s.startswith("```"):
            out.append("\n".join(cur))
            cur = None
        elif cur is not None:
            cur.append(line[len(fence) :] if line.startswith(fence) else line)
    return out


def unprefixed(snippet: str) -> list[str]:
    """The sensorplan ids made without the ``sensorplan_gym:`` prefix in a snippet that does
    not import sensorplan_gym."""
    if re.search(r"^\s*(import sensorplan_gym|from sensorplan_gym\b)", snippet, re.M):
        return []
    return [m for m in MAKE.findall(snippet) if m.startswith("sensorplan/")]


def test_the_check_can_fail():
    bad = 'import gymnasium as gym\nenv = gym.make("sensorplan/Navigate-v0")\n'
    assert unprefixed(bad) == ["sensorplan/Navigate-v0"]
    assert unprefixed(bad.replace('"sensorplan/', '"sensorplan_gym:sensorplan/')) == []
    assert unprefixed("import sensorplan_gym\n" + bad) == []
    md = "text\n  ```python\n  x = gym.make_vec(\n      'sensorplan/Placement-v0')\n  ```\n"
    assert [unprefixed(s) for s in python_snippets(md)] == [["sensorplan/Placement-v0"]]


@pytest.mark.parametrize("path", markdown_files(), ids=lambda p: str(p.relative_to(ROOT)))
def test_snippets_make_envs_that_a_fresh_interpreter_finds(path):
    bad = [ids for s in python_snippets(path.read_text()) if (ids := unprefixed(s))]
    assert not bad, f"{path.name}: use gym.make('sensorplan_gym:sensorplan/...'): {bad}"
