"""Every ``python -m`` entry point of the project answers ``--help`` with its usage and exit
status 0 instead of starting a run.  The entry points are found in the source: every module
with an ``if __name__ == "__main__":`` block (and every package ``__main__.py``)."""

from __future__ import annotations

import ast
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PACKAGES = ("agents", "benchmarks", "geometry", "sensorplan_gym", "tests")
#: entry points whose usage line names the console command rather than ``python -m ...``
PROG = {
    "agents": "sensorplan",
    "agents.cli": "sensorplan",
    "sensorplan_gym.viewer.cli": "sensorplan view",
}


def _is_main_guard(node: ast.stmt) -> bool:
    if not isinstance(node, ast.If) or not isinstance(node.test, ast.Compare):
        return False
    t = node.test
    names = [t.left, *t.comparators]
    return any(isinstance(n, ast.Name) and n.id == "__name__" for n in names) and any(
        isinstance(n, ast.Constant) and n.value == "__main__" for n in names
    )


def entry_points() -> list[str]:
    """The dotted names that ``python -m`` runs: modules with a ``__main__`` guard at module
    level, and packages with a ``__main__.py``."""
    out = []
    for pkg in PACKAGES:
        for f in sorted((ROOT / pkg).rglob("*.py")):
            parts = list(f.relative_to(ROOT).with_suffix("").parts)
            if parts[-1] == "__main__":
                out.append(".".join(parts[:-1]))
                continue
            tree = ast.parse(f.read_text(), filename=str(f))
            if any(_is_main_guard(n) for n in tree.body):
                out.append(".".join(p for p in parts if p != "__init__"))
    return sorted(set(out))


def test_the_entry_points_are_found():
    found = entry_points()
    for m in ("agents", "agents.cli", "benchmarks.reference", "geometry.fuzz",
              "sensorplan_gym.render_rollout", "tests.geometry.test_swept_partial"):  # fmt: skip
        assert m in found, m
    assert "agents.planning.oracle" not in found


@pytest.fixture(scope="module")
def help_runs(tmp_path_factory) -> dict[str, list]:
    """``python -m MODULE --help`` for every entry point, each in a child forked from one fresh
    interpreter that imported the heavy libraries once (``tests/cli/_help_runner.py``), from an
    empty folder (a module that ignored ``--help`` and started writing would leave files there,
    and would be killed after 120 s on its real workload): per module its exit status, stdout,
    stderr and the files it left."""
    out = tmp_path_factory.mktemp("help") / "runs.json"
    code = "import json, sys; from tests.cli._help_runner import run; "
    code += "json.dump(run(sys.argv[2:]), open(sys.argv[1], 'w'))"
    env = {**os.environ, "MPLBACKEND": "Agg", "PYTHONPATH": str(ROOT)}
    subprocess.run(
        [sys.executable, "-c", code, str(out), *entry_points()],
        check=True,
        timeout=60 * len(entry_points()),
        cwd=ROOT,
        env=env,
    )
    return json.loads(out.read_text())


@pytest.mark.parametrize("module", entry_points())
def test_help_prints_usage_and_exits_0(module, help_runs):
    rc, stdout, stderr, left = help_runs[module]
    assert rc == 0, stderr[-2000:]
    prog = PROG.get(module, f"python -m {module}")
    assert stdout.lstrip().startswith(f"usage: {prog} "), stdout[:300]
    assert left == [], "--help wrote files"
