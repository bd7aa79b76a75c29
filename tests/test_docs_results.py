"""Results in the documentation cannot drift from their data.

For every benchmark that writes results (:data:`benchmarks._results.NAMES`) the tracked data
``benchmarks/results/<name>.json`` is rendered again by the benchmark's own ``render`` and
compared with the page fragment ``docs/results/<name>.md``; every fragment must be included by
a documentation page (``--8<-- "docs/results/<name>.md"``), and no page may carry a results
table of its own next to an include.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from benchmarks import _results

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
PAGES = sorted(p for p in DOCS.rglob("*.md") if "results" not in p.relative_to(DOCS).parts)


@pytest.mark.parametrize("name", _results.NAMES)
def test_fragment_is_rendered_from_its_tracked_data(name):
    data_file = _results.DATA_DIR / f"{name}.json"
    fragment = _results.FRAGMENT_DIR / f"{name}.md"
    assert data_file.is_file(), (
        f"no tracked data {data_file}: run the benchmark with --update-results"
    )
    assert fragment.is_file(), f"no page fragment {fragment}"
    want = _results.render(name, _results.load(name))
    got = fragment.read_text(encoding="utf-8")
    assert got == want, (
        f"{fragment} differs from what {data_file.name} renders: regenerate it with "
        f"`{_results.load(name).get('command', 'python -m benchmarks.' + name)} --update-results`"
    )


@pytest.mark.parametrize("name", _results.NAMES)
def test_fragment_is_included_by_a_page(name):
    include = f'--8<-- "docs/results/{name}.md"'
    assert any(include in p.read_text(encoding="utf-8") for p in PAGES), (
        f"no documentation page includes docs/results/{name}.md"
    )


def test_no_other_fragments_or_data():
    """Every fragment and data file belongs to a benchmark in NAMES (no orphaned tables)."""
    names = set(_results.NAMES)
    assert {p.stem for p in _results.FRAGMENT_DIR.glob("*.md")} <= names
    assert {p.stem for p in _results.DATA_DIR.glob("*")} <= names


def test_a_changed_number_is_caught(tmp_path, monkeypatch):
    """The comparison can fail: a fragment edited by hand no longer matches its data."""
    data = _results.load("oracle")
    fragment = (_results.FRAGMENT_DIR / "oracle.md").read_text(encoding="utf-8")
    data["rows"][0]["successes"] -= 1
    assert _results.render("oracle", data) != fragment


def test_pages_quote_no_results_tables_by_hand():
    """Pages that include results fragments carry no hand-written table with timings or
    success rates (a header naming a measured quantity) of their own."""
    measured = re.compile(r"^\|[^\n]*(steps/s|success|median|ms\b| s \|)", re.I | re.M)
    for p in PAGES:
        text = p.read_text(encoding="utf-8")
        if '--8<-- "docs/results/' not in text:
            continue
        body = re.sub(r"```.*?```", "", text, flags=re.S)
        assert not measured.search(body), f"{p.name}: a results table not generated from data"


def test_benchmarks_write_to_out_by_default(tmp_path, monkeypatch):
    """Without --update-results a benchmark writes only into its --out folder."""
    monkeypatch.setattr(_results, "DATA_DIR", tmp_path / "data")
    monkeypatch.setattr(_results, "FRAGMENT_DIR", tmp_path / "fragments")
    d = json.loads((ROOT / "benchmarks" / "results" / "swept.json").read_text())
    paths = _results.write("swept", d, tmp_path / "out", update_results=False)
    assert [p.parent for p in paths] == [tmp_path / "out"] * 2
    assert not (tmp_path / "data").exists() and not (tmp_path / "fragments").exists()
    paths = _results.write("swept", d, tmp_path / "out2", update_results=True)
    assert paths == [tmp_path / "data" / "swept.json", tmp_path / "fragments" / "swept.md"]
    assert not (tmp_path / "out2").exists()


def test_command_drops_the_output_options():
    cmd = _results.command("benchmarks.envs", ["--train", "--out", "x", "--update-results"])
    assert cmd == "python -m benchmarks.envs --train"


def test_reference_report_with_nothing_to_do_says_so(tmp_path, monkeypatch, capsys):
    from benchmarks import reference

    monkeypatch.chdir(tmp_path)
    assert reference.main(["evaluate", "--results", "res"]) == 1
    assert "nothing to evaluate" in capsys.readouterr().out
    assert reference.main(["report", "--results", "res"]) == 1
    assert "nothing to report" in capsys.readouterr().err
    assert not (tmp_path / "runs" / "benchmarks").exists()
    assert (ROOT / "docs" / "results" / "reference.md").read_text(encoding="utf-8") == (
        _results.render("reference", _results.load("reference"))
    )


def test_readme_results_block_is_rendered_from_tracked_data(tmp_path):
    """README.md's results table is what ``benchmarks.readme_results`` renders from the
    tracked data of navigate_hint, recognize_hint and pixel_placement, and it can fail."""
    from benchmarks import readme_results

    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    assert readme_results.block() in readme, (
        "README.md's results block differs from the tracked data: run "
        "`python -m benchmarks.readme_results`"
    )
    assert readme_results.main(["--check"]) == 0
    edited = tmp_path / "README.md"
    edited.write_text(
        readme.replace("| oracle (exact planner) | – | 1.00 |", "| oracle | – | 0.99 |")
    )
    assert readme_results.main(["--check", "--readme", str(edited)]) == 1
    nav = _results.load("navigate_hint")
    text = readme_results.render(nav, _results.load("recognize_hint"))
    # every Navigate policy of the benchmark has its row, imitation beside PPO from scratch
    for name in nav["policies"]:
        assert f"| {readme_results.LABELS.get(name, name)} |" in text
