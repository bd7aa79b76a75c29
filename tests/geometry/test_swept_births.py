"""Shadows born and gone between two samples of a sweep (docs/DESIGN.md, "What is and is not
guaranteed"): a dense-in-time audit of the sweep's union, and the reproduction that found a
sampling rule leaving one out.

On fuzz seed 202333 (contact family; G a point, H a polygon: the mixed 5.2 query) the umbra of
a small obstacle pokes out of the other shadows for about a sixth of one edge of H, a spike born
across an edge that the tracing does not follow (its sweep stays inside the two samples'
shadows) and attached to the shadows, so the birth checks do not see it either.  The wedge rule
(:mod:`geometry._sweep.wedges`) left out the event sample that had caught it, and the
conservative region then held placements 10 ``tol`` deep that see nothing of the target at a
configuration on the boundary of H (CGAL's visibility polygon, below).
"""

from __future__ import annotations

import numpy as np
import pytest
import shapely

from geometry import recognizable_region
from geometry import sweep as S
from tests.geometry.test_sweep_events import _query, _scene

#: fuzz seed 202333: a placement (world frame) inside the spike, and the configuration on the
#: boundary of H (the point at 0.8 of its second edge) where it sees nothing of the target
SEED = 202333
SPIKE = (819199.67543595, 214569.40842636)
EDGE, AT = 1, 0.8


def _blinding_configuration(scene) -> np.ndarray:
    h = np.asarray(scene.failure_geom.exterior.coords)
    return h[EDGE] + AT * (h[EDGE + 1] - h[EDGE])


def test_the_spike_placement_is_blind_there() -> None:
    """The reproduction's premise, from an independent oracle (CGAL via pyvispoly): the
    placement sees no point of the target at that configuration, and does see it at the
    ends of that edge of H."""
    pytest.importorskip("pyvispoly")
    from tests.oracle import VisOracle

    scene = _scene(f"fuzz:{SEED}")
    vis = VisOracle(scene).visibility(np.asarray(SPIKE))
    q = _blinding_configuration(scene)
    assert shapely.intersection(vis, scene.target_at(q[0], q[1], 0.0)).area == 0.0
    h = np.asarray(scene.failure_geom.exterior.coords)
    for end in (h[EDGE], h[EDGE + 1]):
        assert shapely.intersection(vis, scene.target_at(end[0], end[1], 0.0)).area > 0.0


def test_the_conservative_region_leaves_the_spike_out() -> None:
    """``conservative=True`` stays inside the exact region here: the spike's placement is
    not in it (it was, 10 ``tol`` deep, while the wedge rule was on)."""
    scene = _scene(f"fuzz:{SEED}")
    got = recognizable_region(scene, model="partial", theta=0.0, conservative=True)
    assert not shapely.intersects(got, shapely.Point(SPIKE))


def _dense_misses(name: str, query: str, monkeypatch, n_t: int = 41) -> float:
    """The widest part (twice its area over its perimeter, in units of the scene's size) of
    a shadow S(t), at ``n_t`` times along every segment of every sweep of the query, outside
    that sweep's union."""
    segs: list[tuple] = []
    unions: dict[int, shapely.Geometry] = {}
    along, union = S.Sweeper.along_many, S._union_pieces

    def spy(self, pairs, *rest):
        segs.extend((self, np.asarray(a, float), np.asarray(b, float)) for a, b in pairs)
        return along(self, pairs, *rest)

    def keep(sw, pieces):
        unions[id(sw)] = got = union(sw, pieces)
        return got

    with monkeypatch.context() as m:
        m.setattr(S.Sweeper, "along_many", spy)
        m.setattr(S, "_union_pieces", keep)
        _query(name, query, conservative=False)
    widest = 0.0
    for sw, a, b in segs:
        u = unions[id(sw)]
        shapely.prepare(u)
        for t in np.linspace(0.0, 1.0, n_t):
            rest = shapely.get_parts(shapely.difference(sw.shadow(a + t * (b - a))[0], u))
            if len(rest):
                w = 2.0 * shapely.area(rest) / np.maximum(shapely.length(rest), 1e-300)
                widest = max(widest, float(w.max()) / sw.env.scale)
    return widest


@pytest.mark.parametrize(
    ("name", "query"),
    [
        (f"fuzz:{SEED}", "recognizable"),
        ("real/willow_north", "swept"),
        ("real/willow_south", "recognizable"),
        ("fuzz:200049", "recognizable"),
    ],
)
def test_every_shadow_at_dense_times_lies_in_the_union(name, query, monkeypatch) -> None:
    """At 41 times along every segment of every sweep, the exact stationary shadow lies in
    the sweep's union but for parts narrower than ``tol`` (1e-4 of the scene: the traces'
    chords); the spike of seed 202333 was 16 ``tol`` wide."""
    assert _dense_misses(name, query, monkeypatch) <= 1e-4
