"""The certified-bounds fuzz of issue 25 item 2, as a tracked and resumable result.

    python -m benchmarks.fuzz_certify [--n N] [--seed 300000] [--jobs 2] [--chunks DIR]

The swept fuzz of :mod:`benchmarks.fuzz_swept` (every query type, every contact family, each
scene in four frames) with ``certify=True``: on every scene with a polygonal G it also computes
:func:`geometry.certify.swept_bounds` and, for polygonal or mixed G/H, the bounds of the 5.2 /
mixed recognizable region, and requires proven inner ⊆ outer, inner ⊆ outer, the proven inner
inside the stationary partial region at G's vertices and at sampled configurations (on G's
boundary and inside it), and for the recognizable bounds the proven inner inside outer, R(G) and
R(H) (:func:`geometry.fuzz.check_scene`).  A swept-bounds call slower than 30 s counts as a
hang.  Chunks, resuming and ``--update-results`` as in :mod:`benchmarks.fuzz_swept`.
"""

from __future__ import annotations

from typing import Any

from . import fuzz_swept


def main(argv: list[str] | None = None) -> None:
    fuzz_swept.main(argv, name="fuzz_certify", doc=__doc__)


def render(data: dict[str, Any]) -> str:
    """The page fragment: scenes fuzzed with the certified bounds and violations per kind."""
    return fuzz_swept.render(
        data,
        "and the certified bounds of the swept partial region and of the 5.2 / mixed "
        "recognizable region",
    )


if __name__ == "__main__":  # pragma: no cover
    main()
