"""The contact-and-frame fuzz of issue 26 as a tracked result.

    python -m benchmarks.fuzz_contacts [--n 10000] [--seed 100000] [--jobs 16] [--swept]

Runs :func:`geometry.fuzz.run_many` with ``contacts=True, frames=True`` (every contact family
of issue 26: near-duplicate target vertices, flush obstacles over both ends of a target edge,
targets under openings, shared flush edges; every scene also scaled by 1e-3 and 1e3 and moved
to UTM coordinates) and records the violations per kind and the failing seeds.  With
``--swept`` the swept partial and 5.2 recognizable queries are fuzzed too (much slower).
Data (``fuzz_contacts.json``) and fragment (``fuzz_contacts.md``) go to ``--out`` (default
``runs/benchmarks/fuzz_contacts/``), or with ``--update-results`` to the tracked files.
"""

from __future__ import annotations

import argparse
from typing import Any

from geometry.fuzz import run_many

from . import _results

#: The violation kinds of :mod:`geometry.fuzz`, in the table's order.
KINDS = ("crash", "invalid", "outside", "inclusion", "unsafe", "translation", "frame", "hang")


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(
        prog="python -m benchmarks.fuzz_contacts", description=__doc__.split("\n\n")[0]
    )
    ap.add_argument("--n", type=int, default=10_000, help="number of seeds")
    ap.add_argument("--seed", type=int, default=100_000, help="first seed")
    ap.add_argument("--jobs", type=int, default=1, help="processes")
    ap.add_argument("--swept", action="store_true", help="also the swept queries")
    _results.add_output_args(ap, "fuzz_contacts")
    args = ap.parse_args(argv)
    res = run_many(
        args.n, seed=args.seed, contacts=True, frames=True, swept=args.swept, jobs=args.jobs
    )
    data: dict[str, Any] = {
        "command": _results.command("benchmarks.fuzz_contacts", argv),
        "machine": _results.machine(),
        "seeds": [args.seed, args.seed + args.n - 1],
        "swept": args.swept,
        "jobs": args.jobs,
        **res,
    }
    _results.write("fuzz_contacts", data, args.out, args.update_results)


def summary(data: dict[str, Any], head: str) -> str:
    """A fuzz fragment: ``head`` (what was fuzzed), the violations per kind (``KINDS``) as a
    one-row table, the command, and the first 20 failing seeds if any."""
    v = data["violations"]
    lines = [
        head,
        "",
        "| " + " | ".join(KINDS) + " |",
        "|" + "---|" * len(KINDS),
        "| " + " | ".join(str(v.get(k, 0)) for k in KINDS) + " |",
        "",
        f"Measured with `{data['command']}`.",
    ]
    if data["failing_scenes"]:
        seeds = ", ".join(str(f["seed"]) for f in data["failing_scenes"][:20])
        lines += ["", f"Failing seeds: {seeds}."]
    return "\n".join(lines) + "\n"


def render(data: dict[str, Any]) -> str:
    """The page fragment: scenes fuzzed and violations per kind."""
    a, b = data["seeds"]
    what = "every query type" if data["swept"] else "every query type but the swept partial ones"
    return summary(
        data,
        f"Seeds {a}-{b}: {data['valid']} valid scenes of {data['scenes']}, {what}, each scene "
        f"in four frames; {data['seconds']:.0f} s with {data['jobs']} processes.",
    )


if __name__ == "__main__":  # pragma: no cover
    main()
