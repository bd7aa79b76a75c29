"""Where the time of a swept partial query goes, in units of the stationary query.

    python -m benchmarks.swept_phases              # about two minutes
    python -m benchmarks.swept_phases --reps 7 --update-results

For every real map of :mod:`benchmarks.real_maps` (and the fuzzer's slow reproductions), the
swept partial query over G (paper 3.2.2-3.2.3, ``partial_region(target_in="goal")``) split
into the phases of :func:`geometry.sweep.swept_shadows` as its :class:`~geometry.sweep.PhaseClock`
reports them (median over ``--reps`` calls, each on a freshly loaded scene, after one
warm-up call), each as a multiple of the stationary partial query on the same scene measured
in the same run, its calls interleaved with the swept ones and the diagnostics' (the anchor),
with the exact stationary shadows ("samples") each phase took:

* *K's corners*: the one weak visibility region of K = CH(A + G) that tells which obstacle
  corners can graze a beam into the target;
* *vertex samples*: the shadows at the vertices of G;
* *birth checks*: the eroded targets' shadows on every interval, and the samples they bisect
  with;
* *event samples*: the collinearity events and the samples next to the live ones;
* *tracing*: the moving shadow edges traced between the samples (exact point tests) and the
  samples its refinements add;
* *union*: the union of the pieces.

and, as diagnostics, the whole swept query with the samples next to the collinearity events
switched off (what a sweep carrying the shadow edges across the events could at most gain),
and with the birth checks switched off as well (the sweep without either safety net: G's
vertex samples, the tracing between them and the union, the floor of this sweep's design).

The table says which parts a faster sweep has to change: the issue-25 target (10x the
stationary query) is below the cost of the vertex samples plus the birth checks plus the
tracing on the office maps.  Data (``swept_phases.json``) and fragment (``swept_phases.md``) go
to ``--out`` (default ``runs/benchmarks/swept_phases/``) or, with ``--update-results``, to
``benchmarks/results/`` and ``docs/results/``.
"""

from __future__ import annotations

import contextlib
import statistics
import time
from typing import Any
from unittest import mock

import shapely

from geometry import partial_region
from geometry.partial import _swept_region, swept_tol
from geometry.sweep import Sweeper

from .real_maps import SLOW_REPROS, _cases, _pose, cli

#: The phases of the sweep, in the order they run, with their column titles.
PHASES = {
    "anchors": "K's corners",
    "vertex samples": "vertex samples",
    "birth checks": "birth checks",
    "event samples": "event samples",
    "tracing": "tracing",
    "union": "union",
}


def run(reps: int, slow: bool = True) -> dict[str, Any]:
    """Per scene: the stationary partial query's median seconds, the swept query's median
    total and per-phase seconds, its samples per phase, and two diagnostics: ``no_events_s``,
    the swept query's median seconds with the samples next to the collinearity events
    switched off (the most a sweep that carried the shadow edges across the events for free
    could gain; that sweep would keep the samples' safety net, this one drops it, so its
    regions can miss the born-and-gone shadows of the fuzz reproductions), and ``bare_s``,
    with the birth checks switched off too (G's vertex samples, the tracing and the union
    alone: what this sweep costs without either safety net), and ``bare_depth_tol``, how far
    apart that sweep's conservative region and the full one are (:func:`_depth`)."""
    rows = []
    for name, _src, load, theta in _cases():
        if not slow and name in SLOW_REPROS:
            continue
        s = load()
        edges = len(s.bounds) + sum(len(o) for o in s.obstacles)
        partial_region(s, target_at=_pose(s, theta))
        stationary, runs, no_events, bare = [], [], [], []
        for k in range(reps + 1):  # the first call warms up; all four queries interleaved
            if k:
                s = load()
                t0 = time.perf_counter()
                partial_region(s, target_at=_pose(s, theta))
                stationary.append(time.perf_counter() - t0)
            s = load()
            sink: dict[str, Any] = {}
            t0 = time.perf_counter()
            _swept_region(s, "goal", theta, 0.0, 0.0, None, False, sink=sink)
            total = time.perf_counter() - t0
            if k:
                runs.append((total, sink["stats"]))
            for births, times in ((True, no_events), (False, bare)):
                t = _timed(load, theta, births=births)
                if k:
                    times.append(t)
        stats = runs[0][1]
        depth = _depth(load, theta)
        row = {
            "scene": name,
            "edges": edges,
            "theta": theta,
            "stationary_s": statistics.median(stationary),
            "swept_s": statistics.median(t for t, _ in runs),
            "phase_s": {
                p: statistics.median(st["seconds"].get(p, 0.0) for _, st in runs) for p in PHASES
            },
            "rest_s": statistics.median(t - sum(st["seconds"].values()) for t, st in runs),
            "phase_samples": {p: stats["phase_samples"].get(p, 0) for p in PHASES},
            "samples": sum(stats["phase_samples"].values()),
            "no_events_s": statistics.median(no_events),
            "bare_s": statistics.median(bare),
            "bare_depth_tol": depth,
        }
        rows.append(row)
        print(
            f"  {name:>14} stationary {1e3 * row['stationary_s']:6.1f} ms  swept "
            f"{1e3 * row['swept_s']:7.1f} ms  "
            + "  ".join(
                f"{p} {row['phase_s'][p] / row['stationary_s']:.1f}x ({row['phase_samples'][p]})"
                for p in PHASES
            )
        )
    return {"reps": reps, "rows": rows}


def _timed(load, theta: float, *, births: bool) -> float:
    """Seconds of one swept query over G on a freshly loaded scene with the samples next to
    the collinearity events switched off and, unless ``births``, the birth checks too."""
    with contextlib.ExitStack() as stack:
        for patch in _off(births):
            stack.enter_context(patch)
        s = load()
        t0 = time.perf_counter()
        _swept_region(s, "goal", theta, 0.0, 0.0, None, False)
        return time.perf_counter() - t0


def _off(births: bool) -> list:
    """The patches that switch the event samples off and, unless ``births``, the birth
    checks too."""
    off = [mock.patch.object(Sweeper, "_live_mids", lambda self, *a: [])]
    if not births:
        off += [
            mock.patch.object(Sweeper, "_birth_bounds", lambda self, level: ([], {})),
            mock.patch.object(Sweeper, "_refine_births_many", lambda self, *a, **k: None),
        ]
    return off


def _depth(load, theta: float) -> float:
    """How far apart the conservative swept regions over G with and without the safety nets
    (event samples, birth checks) are, in ``tol``: the largest distance of a vertex of either
    one's part outside the other from the other (0: equal)."""
    kw = {"theta": theta, "timeout": None, "conservative": True}
    full = partial_region(load(), target_in="goal", **kw)
    with contextlib.ExitStack() as stack:
        for patch in _off(births=False):
            stack.enter_context(patch)
        bare = partial_region(load(), target_in="goal", **kw)
    out = 0.0
    for a, b in ((full, bare), (bare, full)):
        pts = shapely.get_coordinates(shapely.difference(a, b))
        if len(pts):
            out = max(out, float(shapely.distance(b, shapely.points(pts)).max()))
    return out / swept_tol(load(), None)


def render(data: dict[str, Any]) -> str:
    """The page fragment: per scene the phases as multiples of the stationary partial query
    (samples in parentheses)."""
    lines = [
        "| scene | edges | stationary partial | swept over G | "
        + " | ".join(PHASES.values())
        + " | rest | without event samples | without event samples or birth checks |",
        "| --- | ---: | ---: | ---: |" + " ---: |" * (len(PHASES) + 3),
    ]
    for r in data["rows"]:
        st = r["stationary_s"]
        cells = [
            r["scene"],
            str(r["edges"]),
            f"{1e3 * st:.1f} ms",
            f"{r['swept_s'] / st:.1f}x ({r['samples']})",
        ]
        for p in PHASES:
            n = r["phase_samples"][p]
            cells.append(f"{r['phase_s'][p] / st:.1f}x" + (f" ({n})" if n else ""))
        cells.append(f"{r['rest_s'] / st:.1f}x")
        cells.append(f"{r['no_events_s'] / st:.1f}x")
        depth = r["bare_depth_tol"]
        far = "0" if depth == 0 else "<0.01" if depth < 0.01 else f"{depth:.2g}"
        cells.append(f"{r['bare_s'] / st:.1f}x ({far} tol)")
        lines.append("| " + " | ".join(cells) + " |")
    m = data["machine"]
    lines += [
        "",
        f"`{data['command']}`: medians of {data['reps']} calls, each on a freshly loaded scene "
        "(after one warm-up call), each phase as a multiple of the stationary partial query on "
        "the same scene in the same run, its calls interleaved with those of the swept query "
        "and of the two diagnostics (its median in the third column; the phases' medians need "
        "not add up to the query's); in parentheses the "
        "exact stationary shadows (samples) the phase took; *rest*: the query's own work around "
        "the sweep (the scene's domain, the final difference); *without event samples*: the whole "
        "swept query with the samples next to the collinearity events switched off (a "
        "diagnostic: the bound on what carrying the edges across the events could gain; its "
        "regions lack the events' safety net); *without event samples or birth checks*: the birth "
        "checks switched off as well (the same kind of diagnostic: G's vertex samples, the tracing "
        "and the union alone, the floor of this sweep's design; in parentheses how far its "
        "conservative region lies from the full one's, in `tol`). G a regular pentagon on the real "
        "maps; `slow_1`, `slow_2` the independent fuzzer's reproductions with their own G, "
        f"target and orientation; {m['cpus']} CPUs, Python {m['python']}, load average "
        f"{m['load_average']}.",
    ]
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> None:
    cli("swept_phases", __doc__.split("\n\n")[0], run, render, argv)


if __name__ == "__main__":
    main()
