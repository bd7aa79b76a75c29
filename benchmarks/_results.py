"""Where the benchmarks write: data (JSON) and the page fragment rendered from it.

Every benchmark in this package measures into a plain dictionary (its *data*) and has a pure
``render(data) -> str`` that turns the data into the markdown fragment the documentation
includes.  :func:`write` stores both:

* by default into the ``--out`` folder (``runs/benchmarks/<name>/``; ``runs/`` is
  git-ignored): ``<name>.json`` and ``<name>.md``;
* with ``--update-results`` into the tracked files instead: the data
  ``benchmarks/results/<name>.json`` and the fragment ``docs/results/<name>.md`` that the
  documentation pages include (``--8<-- "docs/results/<name>.md"``).

``tests/test_docs_results.py`` re-renders every fragment from its tracked data, so a page
cannot show a table that its data does not give.
"""

from __future__ import annotations

import argparse
import importlib
import json
import os
import platform
import sys
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
#: tracked data, one JSON file per benchmark
DATA_DIR = ROOT / "benchmarks" / "results"
#: tracked page fragments, included by the documentation pages
FRAGMENT_DIR = ROOT / "docs" / "results"
#: where a run writes without ``--update-results`` (git-ignored)
DEFAULT_OUT = Path("runs") / "benchmarks"
#: the benchmarks that write results (module names under ``benchmarks``)
NAMES = (
    "envs",
    "family_breakdown",
    "fuzz_contacts",
    "fuzz_swept",
    "fuzz_certify",
    "oracle",
    "policies",
    "pool_build",
    "real_maps",
    "regions",
    "scaling",
    "swept",
    "swept_phases",
    "swept_accuracy",
    "train_profile",
    "train_study",
    "viewer_layers",
    "watch_oracle",
    "watch_declare",
    "watch_throughput",
    "reference",
    "pixel_placement",
    "certified",
    "navigate_hint",
    "recognize_hint",
    "recognize_dagger",
    "sweep_audit",
)


def success_cell(row: dict[str, Any] | None) -> str:
    """A table cell for a row with ``successes``, ``episodes`` and ``ci95``: the success rate
    and its 95 % interval, ``"0.90 [0.82, 0.95]"`` (``"–"`` for ``None``)."""
    if row is None:
        return "–"
    lo, hi = row["ci95"]
    return f"{row['successes'] / row['episodes']:.2f} [{lo:.2f}, {hi:.2f}]"


def iqm_rows(res: dict[str, Any]) -> list[dict[str, Any]]:
    """Per split and per config trained at several seeds, the IQM of the success rate over
    the seeds with its stratified-bootstrap 95 % interval, from the result of
    :func:`agents.evaluation.benchmark.benchmark`."""
    return [
        {
            "split": split,
            "config": name,
            "runs": a["n_runs"],
            "train_seeds": a["train_seeds"],
            "iqm": a["iqm"],
            "ci95": list(a["ci95"]),
            "policies": list(a.get("policies") or []),
        }
        for split, r in res["splits"].items()
        for name, a in (r.get("iqm") or {}).items()
    ]


def add_output_args(ap: argparse.ArgumentParser, name: str) -> None:
    """Add ``--out DIR`` and ``--update-results`` to a benchmark's argument parser."""
    ap.add_argument(
        "--out",
        type=Path,
        default=DEFAULT_OUT / name,
        help=f"folder for {name}.json and {name}.md (default {DEFAULT_OUT / name})",
    )
    ap.add_argument(
        "--update-results",
        action="store_true",
        help=f"write the tracked benchmarks/results/{name}.json and docs/results/{name}.md "
        "instead of --out",
    )


def machine() -> dict[str, Any]:
    """What the numbers were measured on: CPU count, platform, Python and the load average."""
    import numpy as np
    import shapely

    try:
        load = round(os.getloadavg()[0], 1)
    except OSError:  # pragma: no cover - not on every platform
        load = None
    return {
        "cpus": os.cpu_count(),
        "machine": platform.machine(),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "shapely": shapely.__version__,
        "load_average": load,
    }


def command(module: str, argv: list[str] | None) -> str:
    """The command line that ran, without the output options (``--out``, ``--update-results``)."""
    args = list(sys.argv[1:] if argv is None else argv)
    kept: list[str] = []
    skip = False
    for a in args:
        if skip:
            skip = False
            continue
        if a == "--update-results":
            continue
        if a == "--out":
            skip = True
            continue
        if a.startswith("--out="):
            continue
        kept.append(a)
    return " ".join(["python -m", module, *kept])


def render(name: str, data: dict[str, Any]) -> str:
    """The page fragment of benchmark ``name`` rendered from ``data`` by its module's
    ``render``; ends with one newline."""
    mod = importlib.import_module(f"benchmarks.{name}")
    return mod.render(data).rstrip("\n") + "\n"


def write(name: str, data: dict[str, Any], out: Path, update_results: bool) -> list[Path]:
    """Write ``data`` (JSON) and its rendered fragment (markdown): into the folder ``out`` or,
    with ``update_results``, into the tracked files.  The data is written first, so that a
    fragment can always be rendered again from it.  Returns the two paths written."""
    if update_results:
        paths = [DATA_DIR / f"{name}.json", FRAGMENT_DIR / f"{name}.md"]
    else:
        paths = [Path(out) / f"{name}.json", Path(out) / f"{name}.md"]
    for p in paths:
        try:
            p.parent.mkdir(parents=True, exist_ok=True)
        except OSError as e:
            msg = f"cannot create the output folder {p.parent}: {e.strerror or e}"
            raise SystemExit(msg) from None
    paths[0].write_text(json.dumps(data, indent=1, ensure_ascii=False) + "\n", encoding="utf-8")
    paths[1].write_text(render(name, data), encoding="utf-8")
    print(f"wrote {paths[0]} and {paths[1]}")
    return paths


def load(name: str) -> dict[str, Any]:
    """The tracked data of benchmark ``name``."""
    return json.loads((DATA_DIR / f"{name}.json").read_text(encoding="utf-8"))
