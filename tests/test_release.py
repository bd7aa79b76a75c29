"""Release hygiene: the version is written in one place (``sensorplan_gym.__version__``) and
everything that reports a version reads it; the changelog has a section for it."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

import pytest

import sensorplan_gym

ROOT = Path(__file__).resolve().parents[1]
VERSION = re.compile(r"""^__version__\s*=\s*["']([^"']+)["']\s*$""", re.M)


def test_the_version_is_written_once():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())
    assert "version" not in project["project"], "pyproject.toml must not repeat the version"
    assert "version" in project["project"]["dynamic"]
    attr = project["tool"]["setuptools"]["dynamic"]["version"]["attr"]
    assert attr == "sensorplan_gym.__version__"
    # one __version__ assignment in the packages, a plain string setuptools reads statically
    found = {
        str(f.relative_to(ROOT)): VERSION.findall(f.read_text())
        for pkg in ("geometry", "sensorplan_gym", "agents", "benchmarks")
        for f in (ROOT / pkg).rglob("*.py")
        if "__version__ =" in f.read_text()
    }
    assert found == {"sensorplan_gym/__init__.py": [sensorplan_gym.__version__]}
    assert re.fullmatch(r"\d+\.\d+\.\d+(?:[ab]\d+|rc\d+|\.dev\d+)?", sensorplan_gym.__version__)


def test_training_records_that_version():
    train = pytest.importorskip("agents.learning.train")
    assert train.package_version() == sensorplan_gym.__version__


def test_the_changelog_has_the_version():
    text = (ROOT / "CHANGELOG.md").read_text()
    sections = re.findall(r"^## \[([^\]]+)\]", text, re.M)
    assert sections[0] == "Unreleased"
    assert sensorplan_gym.__version__ in sections
    for v in sections[1:]:
        assert re.search(rf"^## \[{re.escape(v)}\] - \d{{4}}-\d{{2}}-\d{{2}}$", text, re.M), v


def test_ci_builds_and_checks_the_distributions():
    ci = (ROOT / ".ci" / "run").read_text()
    assert "python -m build" in ci and "twine check" in ci
    dev = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"][
        "dev"
    ]
    assert {"build", "twine"} <= {re.split(r"[<>=\[ ]", d)[0] for d in dev}
