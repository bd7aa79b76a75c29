"""The swept fuzz of issues 25 and 26, in every frame, as a tracked and resumable result.

    python -m benchmarks.fuzz_swept [--n 10200] [--seed 200000] [--jobs 2] [--chunks DIR]

Runs :func:`geometry.fuzz.run_many` with ``swept=True, contacts=True, frames=True`` (every
query type, the swept partial region and the 5.2 recognizable region included, on scenes with
every contact family of issue 26; each scene also scaled by 1e-3 and 1e3 and moved to UTM
coordinates) in chunks of ``--chunk`` seeds.  Each chunk's summary is written to
``DIR/chunk_<first seed>.json`` as soon as it is done, and a rerun skips the chunks already
there, so a run that was cut off goes on where it stopped (a swept scene costs about 1.6 s of
one core in four frames: 10,000 scenes are about 4.5 core-hours).  The chunks are then merged
into the data.  ``DIR`` defaults to ``runs/benchmarks/fuzz_swept/chunks``.  Data
(``fuzz_swept.json``) and fragment (``fuzz_swept.md``) go to ``--out`` or, with
``--update-results``, to the tracked files.  The same chunk files come from
``python -m geometry.fuzz --n N --seed S --swept --frames --contacts --json DIR/chunk_S.json``.
"""

from __future__ import annotations

import argparse
import json
from collections import Counter
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

from geometry.fuzz import run_many

from . import _results
from .fuzz_contacts import summary


def _chunk(arg: tuple[int, int, str, bool]) -> str:
    """Fuzz one chunk (``n`` seeds from ``seed``; with the certified bounds if ``certify``)
    and write its summary to ``path``."""
    seed, n, path, certify = arg
    res = run_many(n, seed=seed, swept=True, contacts=True, frames=True, certify=certify)
    tmp = Path(path).with_suffix(".tmp")
    tmp.write_text(json.dumps(res, indent=1) + "\n", encoding="utf-8")
    tmp.replace(path)  # a chunk file is whole or absent
    return path


def merge(paths: list[Path]) -> dict[str, Any]:
    """The chunk summaries (:func:`geometry.fuzz.run_many`'s dictionaries) merged: scenes,
    valid scenes and violations summed, failing scenes listed by seed, the slowest time of
    every query, and ``seconds``: the chunks' times summed (process seconds, not wall)."""
    kinds: Counter[str] = Counter()
    failing: list[dict[str, Any]] = []
    slowest: dict[str, float] = {}
    scenes = valid = 0
    seconds = 0.0
    for p in paths:
        r = json.loads(p.read_text(encoding="utf-8"))
        scenes += r["scenes"]
        valid += r["valid"]
        seconds += r["seconds"]
        kinds.update(r["violations"])
        failing += r["failing_scenes"]
        for k, v in r["slowest_query_s"].items():
            slowest[k] = max(slowest.get(k, 0.0), v)
    return {
        "scenes": scenes,
        "valid": valid,
        "violations": dict(kinds),
        "failing_scenes": sorted(failing, key=lambda f: f["seed"]),
        "slowest_query_s": dict(sorted(slowest.items())),
        "seconds": round(seconds, 1),
    }


def main(argv: list[str] | None = None, *, name: str = "fuzz_swept", doc: str = "") -> None:
    """Run the chunks and write the merged data as ``name`` (``fuzz_certify``: with the
    certified bounds of :func:`geometry.certify.swept_bounds` on every scene)."""
    certify = name == "fuzz_certify"
    ap = argparse.ArgumentParser(
        prog=f"python -m benchmarks.{name}", description=(doc or __doc__).split("\n\n")[0]
    )
    ap.add_argument("--n", type=int, default=10_200, help="number of seeds")
    ap.add_argument("--seed", type=int, default=200_000, help="first seed")
    ap.add_argument("--chunk", type=int, default=50, help="seeds per chunk (default 50)")
    ap.add_argument("--jobs", type=int, default=1, help="processes")
    ap.add_argument(
        "--chunks",
        type=Path,
        default=_results.DEFAULT_OUT / name / "chunks",
        help="folder of the chunk summaries (kept; a rerun skips the chunks there)",
    )
    _results.add_output_args(ap, name)
    args = ap.parse_args(argv)
    for opt in ("n", "chunk", "jobs"):
        if getattr(args, opt) < 1:
            ap.error(f"--{opt} must be a positive integer, got {getattr(args, opt)}")
    args.chunks.mkdir(parents=True, exist_ok=True)
    starts = range(args.seed, args.seed + args.n, args.chunk)
    paths = [args.chunks / f"chunk_{s}.json" for s in starts]
    todo = [
        (s, min(args.chunk, args.seed + args.n - s), str(p), certify)
        for s, p in zip(starts, paths, strict=True)
        if not p.exists()
    ]
    print(f"{len(paths) - len(todo)} of {len(paths)} chunks already in {args.chunks}")
    if todo:
        with ProcessPoolExecutor(args.jobs) as ex:
            for done in ex.map(_chunk, todo):
                print("wrote", done, flush=True)
    data: dict[str, Any] = {
        "command": _results.command(f"benchmarks.{name}", argv),
        "machine": _results.machine(),
        "seeds": [args.seed, args.seed + args.n - 1],
        "chunk": args.chunk,
        **merge(paths),
    }
    _results.write(name, data, args.out, args.update_results)


def render(
    data: dict[str, Any],
    what: str = "including the swept partial region and the 5.2 recognizable region",
) -> str:
    """The page fragment: scenes fuzzed (every query type, ``what``) and violations per kind."""
    a, b = data["seeds"]
    return summary(
        data,
        f"Seeds {a}-{b}: {data['valid']} valid scenes of {data['scenes']}, every query type "
        f"{what}, each scene in four frames; {data['seconds'] / 3600.0:.1f} process-hours in "
        f"chunks of {data['chunk']} seeds.",
    )


if __name__ == "__main__":  # pragma: no cover
    main()
