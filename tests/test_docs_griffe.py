"""The API pages' docstring conversion (docs/griffe_docstrings.py): NumPy-like sections become
bold headers and bullet lists, reST roles code spans; other text is left alone."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

pytest.importorskip("griffe")
ROOT = Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location(
    "griffe_docstrings", ROOT / "docs" / "griffe_docstrings.py"
)
gd = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(gd)


def test_sections_become_lists():
    doc = (
        "Do it.\n\nParameters\n----------\nscene : the scene.\ntheta : the angle;\n"
        "    in radians.\n\nReturns\n-------\nA polygon, see :func:`~geometry.sweep.x`.\n"
    )
    out = gd.markdown(doc)
    assert "**Parameters**" in out and "**Returns**" in out
    assert "- `scene`: the scene." in out
    assert "- `theta`: the angle; in radians." in out
    assert "see `geometry.sweep.x`." in out
    assert "----" not in out


def test_plain_text_is_unchanged():
    doc = "One line.\n\nA paragraph with a : colon\nand ``code``."
    assert gd.markdown(doc) == doc
