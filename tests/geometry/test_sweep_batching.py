"""The batched helpers of :class:`geometry.sweep.Sweeper` agree with their one-at-a-time
definitions (issue 25 item 1: speed without changing answers)."""

from __future__ import annotations

import json
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import shapely

from geometry import Scene, partial_region, recognizable_region
from geometry import sweep as S
from geometry._shapes import cross as _cross
from geometry._sweep import shadow as SH
from geometry._sweep.lines import _rot

REPRO = Path(__file__).parent / "fuzz_repro"


def _drop_short_loop(v: np.ndarray, length: float) -> np.ndarray:
    keep = [0]
    for i in range(1, len(v)):
        if np.abs(v[i] - v[keep[-1]]).max() >= length:
            keep.append(i)
    while len(keep) > 1 and np.abs(v[keep[-1]] - v[0]).max() < length:
        keep.pop()
    return v[keep]


def test_drop_short_matches_the_loop() -> None:
    rng = np.random.default_rng(7)
    for _ in range(200):
        v = np.cumsum(rng.normal(size=(12, 2)), axis=0)
        k = rng.integers(0, 4)
        for i in rng.integers(0, len(v), size=k):  # short edges, incl. the closing one
            v[i] = v[i - 1] + 1e-9
        got, ref = SH._drop_short(v, 1e-6), _drop_short_loop(v, 1e-6)
        # the same vertices kept, each moved at most to its split corner (SH._corners)
        assert got.shape == ref.shape
        assert np.abs(got - ref).max() <= 4e-6
        assert int((np.abs(got - ref) > 0).any(axis=1).sum()) <= k


def test_drop_short_of_many_rings_is_ring_by_ring() -> None:
    """_drop_short_many gives each ring what _drop_short gives it (the very array where
    nothing is dropped), over batches mixing rings with and without short steps, short
    closing steps, and rings of zero to two vertices; and _ring_coords reads shapely's
    rings as their coordinates do."""
    rng = np.random.default_rng(11)
    slow = 0
    for _ in range(300):
        rings = []
        for _ in range(rng.integers(1, 6)):
            n = int(rng.choice([0, 1, 2, 5, 12]))
            v = np.cumsum(rng.normal(size=(n, 2)), axis=0)
            for i in rng.integers(0, max(n, 1), size=rng.integers(0, 3)) if n else []:
                v[i] = v[i - 1] + 1e-9  # a short step (the closing one when i == 0)
            rings.append(v)
        got = SH._drop_short_many(rings, 1e-6)
        for v, g in zip(rings, got, strict=True):
            ref = SH._drop_short(v, 1e-6)
            assert (g is v) == (ref is v)
            assert np.array_equal(g, ref)
            slow += g is not v
    assert slow > 50  # not vacuous: many rings took the slow path
    polys = shapely.buffer(shapely.points(rng.normal(size=(4, 2)) * 5), 1.0)
    shapely.prepare(polys)
    rings = SH._rings(shapely.difference(shapely.box(-20, -20, 20, 20), shapely.union_all(polys)))
    assert len(rings) > 1
    for r, c in zip(rings, SH._ring_coords(rings), strict=True):
        assert np.array_equal(c, np.asarray(r.coords)[:-1, :2])


def _split_ring(rng: np.random.Generator, length: float) -> tuple[np.ndarray, np.ndarray]:
    """A random star-shaped ring whose corners are replaced, at random, by clusters of 2-4
    vertices closer than ``length``: split corners (on the two edges' lines, or a few
    ulps off them), and short edges whose vertices lie off both lines; the closing step is
    short in some.  Also, per vertex, an environment vertex id or -1 (for ``vertex_at``)."""
    n = int(rng.integers(4, 12))
    ang = np.sort(rng.uniform(0, 2 * np.pi, n))
    base = np.stack([np.cos(ang), np.sin(ang)], axis=1) * rng.uniform(1, 3, (n, 1))
    # straight "corners" (an edge's midpoint): there the lines into and out of a cluster
    # are nearly parallel and cross far from it (the short-edge case of _corners)
    mids = 0.5 * (base + np.roll(base, -1, axis=0))
    straight = rng.random(n) < 0.3
    base = np.stack([base, mids], axis=1).reshape(-1, 2)[
        np.repeat([True], 2 * n) & np.ravel(np.stack([np.ones(n, dtype=bool), straight], axis=1))
    ]
    n = len(base)
    pts, ids = [], []
    for i, c in enumerate(base):
        k = int(rng.choice([1, 1, 2, 3, 4]))
        if k == 1:
            pts.append(c)
            ids.append(int(rng.choice([-1, i])))
            continue
        u_in = c - base[i - 1]
        u_out = base[(i + 1) % n] - c
        u_in, u_out = u_in / np.hypot(*u_in), u_out / np.hypot(*u_out)
        off_line = rng.random() < 0.3  # a short edge of its own, not a split corner
        for j in range(k):
            f = (j + 0.5) / k - 0.5  # from before the corner to after it
            p = c + (f * length * 0.6) * (u_in if f < 0 else u_out)
            if off_line:
                p = p + rng.normal(size=2) * length * 0.2
            elif rng.random() < 0.3:
                p = p + rng.normal(size=2) * 1e-15
            pts.append(p)
            ids.append(int(rng.choice([-1, 100 * i + j])))
    v, at = np.asarray(pts), np.asarray(ids)
    r = int(rng.integers(0, len(v)))  # a cluster may straddle the closing step
    return np.roll(v, r, axis=0), np.roll(at, r)


def test_drop_short_batches_the_tight_runs_as_ring_by_ring(monkeypatch) -> None:
    """The rings whose runs of short steps are all tight (geometry._sweep.shadow._tight_runs:
    split corners of 2-4 vertices, short edges between vertices of the environment) get
    from the batch exactly what _drop_short gives them one by one, bit for bit; the batch
    and the ring-by-ring fallback (a cluster across the closing step) both run."""
    rng = np.random.default_rng(23)
    length = 1e-6
    calls = {"one": 0}
    one = SH._drop_short

    def counted(*a, **k):
        calls["one"] += 1
        return one(*a, **k)

    batched = 0
    for _ in range(300):
        made = [_split_ring(rng, length) for _ in range(int(rng.integers(1, 6)))]
        rings = [v for v, _ in made]
        table = np.concatenate([v for v in rings])
        ids = np.concatenate([a for _, a in made])

        def vertex_at(p, table=table, ids=ids):
            near = (np.abs(table[None] - p[:, None]) == 0).all(axis=2)
            return np.where(near.any(axis=1), ids[np.argmax(near, axis=1)], -1)

        monkeypatch.setattr(SH, "_drop_short", counted)
        before = calls["one"]
        got = SH._drop_short_many(rings, length, vertex_at)
        monkeypatch.setattr(SH, "_drop_short", one)
        with_short = sum(
            bool((np.abs(np.roll(v, -1, axis=0) - v).max(axis=1) < length).any()) for v in rings
        )
        batched += with_short - (calls["one"] - before)
        for v, g in zip(rings, got, strict=True):
            ref = one(v, length, vertex_at)
            assert g.shape == ref.shape
            assert np.array_equal(g.view(np.int64), ref.view(np.int64))  # -0.0 too
    assert batched > 300 and calls["one"] > 50  # both paths taken, many times
    # a ring whose cluster straddles its closing step, after a ring with a run where its
    # vertex 0 is (rings touch at a vertex): the run of the one must not pass for the other's
    b = np.array([[3.0, 3.0], [4.0, 3.0], [4.0, 4.0], [0.0, 0.0], [3e-7, 1e-7]])
    a = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [-3e-7, 2e-7]])
    c = np.array([[5.0, 5.0], [6.0, 5.0], [6.0, 6.0], [5.0, 6.0]])
    # a run whose next vertex, after a long step, is back within ``length`` of the run's
    # first (the greedy drops it too): not tight
    d = np.array([[0.0, 0.0], [6e-7, 0.0], [-5e-7, 0.0], [1.0, 0.5], [0.5, 1.0]])
    for g, v in zip(SH._drop_short_many([b, a, c, d], length), [b, a, c, d], strict=True):
        assert np.array_equal(g, one(v, length))
    tiny = a * 1e-7  # every step short, in the only ring
    assert np.array_equal(SH._drop_short_many([tiny], length)[0], one(tiny, length))


def _sweeper(monkeypatch, scene: Scene | None = None) -> S.Sweeper:
    """The sweeper of the swept partial query over G on ``scene`` (default ``lab``)."""
    got = {}
    orig = S.Sweeper.along_many

    def along_many(self, *a, **k):
        got.setdefault("sw", self)
        return orig(self, *a, **k)

    monkeypatch.setattr(S.Sweeper, "along_many", along_many)
    scene = scene or Scene.load("sensorplan_gym/scenes/lab.json")
    partial_region(scene, target_in="goal", theta=0.0)
    return got["sw"]


def test_batched_labels_equal_ring_by_ring(monkeypatch) -> None:
    sw = _sweeper(monkeypatch)
    n_moving = 0
    for key in list(sw._frames)[:6]:
        shadow, table, tid = sw.shadow(np.asarray(key))
        for ring in SH._rings(shapely.orient_polygons(shadow, exterior_cw=False)):
            v = SH._drop_short(np.asarray(ring.coords)[:-1, :2], sw.tol_lab)
            one = sw._label(v, table, tid)
            d = np.roll(v, -1, axis=0) - v
            both = sw._label(np.vstack([v, v[::-1]]), table, tid, d=np.vstack([d, -d[::-1]]))
            assert np.array_equal(both[: len(v)], one)
            n_moving += int((one >= sw.n_fixed).any(axis=1).sum())
    assert n_moving > 0


def test_edges_of_many_shadows_are_shadow_by_shadow(monkeypatch) -> None:
    """_edges_many labels the rings of several shadows in one batch, each row against its
    own shadow's anchor table (padded to one length): every shadow gets the edges it gets
    alone, bit for bit (the 5.2 sweeps of ``lab`` and its swept query); and rows against
    tables of different lengths (overlap strips that cut the outline add anchors) get
    what each table gives them alone."""
    sweepers = []
    orig = S.Sweeper.along_many

    def along_many(self, *a, **k):
        sweepers.append(self)
        return orig(self, *a, **k)

    monkeypatch.setattr(S.Sweeper, "along_many", along_many)
    scene = Scene.load("sensorplan_gym/scenes/lab.json")
    recognizable_region(scene, model="partial", theta=0.0)
    partial_region(scene, target_in="goal", theta=0.0)
    moving = 0
    for sw in sweepers:
        shadows = [sw.shadow(np.asarray(key)) for key in sw._frames]
        batch = sw._edges_many(shadows)
        for sh, got in zip(shadows, batch, strict=True):
            assert got == sw._edges_many([sh])[0]
            moving += len(got)
        assert batch == [e for _, e in sw._frames.values()]  # what the sweep kept
    assert len(sweepers) == 3 and moving > 20
    # padding: the second table is the first with three more moving anchors (on no
    # edge's line) ahead of the target's, the third the first without its last target
    # vertex
    sw = sweepers[-1]
    rows, tables, of, n_rows = [], [], [], 0
    for key in list(sw._frames)[:4]:
        shadow, table, tid = sw.shadow(np.asarray(key))
        v = np.concatenate(SH._ring_coords(SH._rings(shapely.orient_polygons(shadow))))
        d = np.roll(v, -1, axis=0) - v
        extra = np.array([[1e3, 7e2], [-3e3, 1.1e3], [5e2, -2.9e3]])
        n = sw.n_fixed  # the extra anchors before the target's: the columns shift
        more = (
            np.vstack([table[:n], extra, table[n:]]),
            np.concatenate([tid[:n], tid.max() + 1 + np.arange(3), tid[n:]]),
        )
        fewer = (table[:-1], tid[:-1])
        for t in ((table, tid), more, fewer):
            rows.append((v, d, sw._label(v, *t, d=d)))
            tables.append(t)
            of.append(np.full(len(v), len(tables) - 1))
            n_rows += len(v)
    v_all = np.concatenate([r[0] for r in rows])
    d_all = np.concatenate([r[1] for r in rows])
    got = sw._label_rows(v_all, d_all, tables, np.concatenate(of))
    assert np.array_equal(got, np.concatenate([r[2] for r in rows]))
    assert len({len(t) for t, _ in tables}) == 3 and (got >= sw.n_fixed).any()
    # the order of the rows does not matter either
    perm = np.random.default_rng(3).permutation(n_rows)
    again = sw._label_rows(v_all[perm], d_all[perm], tables, np.concatenate(of)[perm])
    assert np.array_equal(again, got[perm])


def _all_at_once(sw: S.Sweeper, vs, ve, ts, q0, dq) -> tuple[np.ndarray, np.ndarray]:
    """Validity with every probe tested at once (the definition), and with the first
    round's probes only."""
    d = ve - vs
    ln = np.hypot(d[..., 0], d[..., 1])
    with np.errstate(divide="ignore", invalid="ignore"):
        u = d / ln[..., None]
    h = np.minimum(sw.h, 0.05 * ln)[..., None]
    nrm = _rot(u) * (1e-3 * h)
    fixed = np.broadcast_to(np.arange(1, sw.probes) / sw.probes, ln.shape + (sw.probes - 1,))
    fr = np.concatenate([fixed, sw._between_lines(vs, d, ts, q0, dq)], axis=-1)
    eh = (h[..., 0] / np.where(ln > 0, ln, 1.0))[..., None]
    fr = np.clip(np.where(np.isfinite(fr), fr, 0.5), eh, 1 - eh)
    ends = np.stack([vs + h * u + nrm, ve - h * u + nrm], axis=-2)
    inner = vs[..., None, :] + fr[..., None] * d[..., None, :] + nrm[..., None, :]
    q = q0 + ts[..., None] * dq
    every = sw._probes_blind(np.concatenate([ends, inner], axis=-2), q) & (ln > 0)
    first = sw._probes_blind(np.concatenate([ends, inner[..., : sw.probes - 1, :]], axis=-2), q)
    return every, first & (ln > 0)


def _traced_steps(sw: S.Sweeper):
    """Per pair of consecutive sampled configurations with shadow edges: ``(q0, dq, ts, vs,
    ve)``, the edges' ends at 9 times between them (what ``_valid_many`` checks)."""
    keys = [np.asarray(k) for k in sw._frames]
    for q0, q1 in zip(keys[:-1], keys[1:], strict=True):
        dq = q1 - q0
        edges = sw._edges(*sw.shadow(q0))
        if not edges or not np.hypot(*dq) > 0:
            continue
        ts = np.broadcast_to(np.linspace(0.0, 1.0, 9), (len(edges), 9))
        vs, ve = sw._ends_many(edges, ts, q0, dq)
        yield q0, dq, ts, vs, ve


def test_two_round_probing_equals_testing_every_probe(monkeypatch) -> None:
    sw = _sweeper(monkeypatch)
    by_second = 0
    for q0, dq, ts, vs, ve in _traced_steps(sw):
        got = sw._valid_many(vs, ve, ts, q0, dq)
        every, first = _all_at_once(sw, vs, ve, ts, q0, dq)
        assert np.array_equal(got, every)
        by_second += int((first & ~every).sum())
    assert by_second > 0  # not vacuous: the second round decides some of them


def _unfiltered(sw: S.Sweeper) -> tuple[np.ndarray, ...]:
    """Every convex corner, and every pair tangent at both (no "sees K" filter)."""
    env = sw.env
    b = env.vert[env.reflex]
    bp = env.vert_prev[env.reflex] - b
    bn = env.vert_next[env.reflex] - b
    i, j = np.triu_indices(len(b), 1)
    w = b[j] - b[i]
    ok = (_cross(w, bp[i]) * _cross(w, bn[i]) >= 0) & (_cross(w, bp[j]) * _cross(w, bn[j]) >= 0)
    return b, bp, bn, i[ok], j[ok]


def test_probing_only_lines_into_k_equals_probing_all(monkeypatch) -> None:
    """The corners that do not see K and the corner pairs whose line misses K are not
    probed between: the traced edges' validity is the same as with all of them."""
    sw = _sweeper(monkeypatch)
    full = _unfiltered(sw)
    got = sw._corners_and_tangents()
    assert len(got[0]) < len(full[0]) and len(got[3]) < len(full[3])  # not vacuous
    checked = 0
    for q0, dq, ts, vs, ve in _traced_steps(sw):
        filtered = sw._valid_many(vs, ve, ts, q0, dq)
        monkeypatch.setattr(sw, "_tangents", full)
        every = sw._valid_many(vs, ve, ts, q0, dq)
        monkeypatch.setattr(sw, "_tangents", got)
        assert np.array_equal(filtered, every)
        checked += filtered.size
    assert checked > 0


def test_skipping_fixed_edges_keeps_the_labels(monkeypatch) -> None:
    """Edges between two environment vertices are not labelled: the moving edges and
    their neighbours' keys are those of labelling every edge."""
    sw = _sweeper(monkeypatch)
    skipped = 0
    for key in list(sw._frames)[:8]:
        shadow, table, tid = sw.shadow(np.asarray(key))
        fast = sw._edges(shadow, table, tid)
        rings = SH._rings(shapely.orient_polygons(shadow, exterior_cw=False))
        vs = [
            v
            for r in rings
            if len(v := SH._drop_short(np.asarray(r.coords)[:-1, :2], sw.tol_lab)) >= 3
        ]
        off = np.cumsum([0] + [len(v) for v in vs])
        skipped += int(sw._fixed_edges(np.concatenate(vs), off).sum())
        monkeypatch.setattr(sw, "_fixed_edges", lambda v, off: np.zeros(len(v), dtype=bool))
        slow = sw._edges(shadow, table, tid)
        monkeypatch.delattr(sw, "_fixed_edges")
        assert fast == slow
    assert skipped > 0


def _moving_edges(sw: S.Sweeper):
    """``(q0, dq, edges)`` between consecutive samples of ``sw``: the shadow edges on moving
    lines at ``q0`` and the step to the next sample (where both exist)."""
    keys = [np.asarray(k) for k in sw._frames]
    for q0, q1 in zip(keys[:-1], keys[1:], strict=True):
        edges = sw._edges(*sw.shadow(q0))
        if edges and np.hypot(*(q1 - q0)) > 0:
            yield q0, q1 - q0, edges


def test_batched_bisection_equals_step_by_step(monkeypatch) -> None:
    """The death-time bisection in rounds of several levels returns the times of the
    bisection one step at a time (bit for bit), whatever the validity along the way (the
    previous rules: every step; the lazy rules stop early, see the next test)."""
    sw = _sweeper(monkeypatch)
    sw.lazy_samples = False
    moved = 0
    for q0, dq, edges in _moving_edges(sw):
        t_ok, t_bad = np.zeros(len(edges)), np.ones(len(edges))
        for _ in range(sw.bisect_steps):  # the definition
            tm = 0.5 * (t_ok + t_bad)
            a, b = sw._ends_many(edges, tm[:, None], q0, dq)
            good = sw._valid_many(a, b, tm[:, None], q0, dq)[:, 0]
            t_ok = np.where(good, tm, t_ok)
            t_bad = np.where(good, t_bad, tm)
        got, got_bad = sw._bisect(edges, np.zeros(len(edges)), np.ones(len(edges)), q0, dq)
        assert np.array_equal(got, t_ok)
        assert np.array_equal(got_bad, t_bad)
        moved += int(((got > 0) & (got < 0.99)).sum())
    assert moved > 0  # not vacuous: some edges die inside the interval


def test_skipping_corners_blind_to_k_keeps_the_shadows(monkeypatch) -> None:
    """The stationary shadows of a sweep skip the grazing anchors that see no point of K:
    the shadows are those with every anchor (bit for bit)."""
    sw = _sweeper(monkeypatch)
    mask = sw._anchors()
    assert 0 < mask.sum() < sw.env.reflex.sum()  # not vacuous: some corners are skipped
    for key in list(sw._frames)[:8]:
        q = np.asarray(key)
        sw._grazing = mask
        fast = sw.shadow(q)[0]
        sw._grazing = None
        slow = sw.shadow(q)[0]
        assert shapely.equals_exact(fast, slow, 0.0)


def _sweep_with_pieces(monkeypatch, scene: str) -> tuple[S.Sweeper, list]:
    """A swept query on ``scene``: its sweeper and the pieces it united."""
    got: dict = {}
    orig_along, orig_union = S.Sweeper.along_many, S._union_pieces

    def along_many(self, *a, **k):
        got.setdefault("sw", self)
        return orig_along(self, *a, **k)

    def union(sw, pieces):
        got["pieces"] = list(pieces)
        return orig_union(sw, pieces)

    monkeypatch.setattr(S.Sweeper, "along_many", along_many)
    monkeypatch.setattr(S, "_union_pieces", union)
    partial_region(Scene.load(f"sensorplan_gym/scenes/{scene}.json"), target_in="goal", theta=0.0)
    return got["sw"], got["pieces"]


def test_union_from_what_the_samples_do_not_hold_equals_the_union_of_the_pieces(
    monkeypatch,
) -> None:
    """F - (X_1 n ... n X_n), united with the traced quads, is the union of the sampled
    shadows S_k = F - X_k and the quads (up to the snap-rounding grid)."""
    for scene in ("lab", "real/willow_south"):
        sw, pieces = _sweep_with_pieces(monkeypatch, scene)
        frames = {id(v[0]) for v in sw._frames.values()}
        n_frames = sum(id(p) in frames for p in pieces)
        assert n_frames >= 2 and len(pieces) > n_frames  # samples and traced quads
        assert all(k in sw._seen for k in sw._frames)  # the De Morgan path, not the fallback
        fast = S._union_pieces(sw, pieces)
        slow = S.polygonal(S.union_all(pieces, grid_size=sw.grid))
        diff = shapely.symmetric_difference(fast, slow).area
        # a band of a few grid cells along the boundary at most
        assert diff <= 8 * sw.grid * shapely.length(slow), (scene, diff)
        assert abs(fast.area - slow.area) <= 1e-9 * slow.area


def test_uncovered_from_what_the_samples_do_not_hold_equals_uncovered_by_their_union(
    monkeypatch,
) -> None:
    """The edges whose sweep leaves the two samples' shadows, found from X_a n X_b, are
    those found from the union of the two shadows (the definition)."""
    calls = {"n": 0, "traced": 0}
    orig = S.Sweeper._uncovered_seen_many

    def both(self, items):
        out = orig(self, items)
        for (edges, t, toward, ab, q0, q1), got in zip(items, out, strict=True):
            if edges:
                ka, kb = (self._frame_key(q0, q1, u) for u in ab)
                known = S.areal(shapely.union(self._frames[ka][0], self._frames[kb][0]))
                assert got == self._uncovered(edges, t, toward, known, q0, q1 - q0)
                # the batch gives each item what it gives alone
                assert got == orig(self, [(edges, t, toward, ab, q0, q1)])[0]
                calls["n"] += 1
                calls["traced"] += len(got)
        return out

    monkeypatch.setattr(S.Sweeper, "_uncovered_seen_many", both)
    for scene in ("lab", "edr"):
        partial_region(
            Scene.load(f"sensorplan_gym/scenes/{scene}.json"), target_in="goal", theta=0.0
        )
    # not vacuous: edges were tested, and some of them swept outside the known shadows
    assert calls["n"] > 10 and calls["traced"] > 0


def test_batched_weak_visibility_is_the_one_by_one_answer(monkeypatch) -> None:
    """weak_visibility_many gives, bit for bit, what weak_visibility gives target by
    target: on the targets a sweep samples (whole outline, and the 5.2 outlines with
    unwanted pieces) and on targets flush against obstacles (fuzz contact scenes).  (The
    same coordinates in the same order: the snap-rounded union can round a coordinate to
    -0.0 in one and 0.0 in the other, which compare equal.)"""
    from geometry import recognizable_region
    from geometry._common import scene_domain
    from geometry._shapes import ccw_ring
    from geometry.fuzz import fuzz_scene
    from geometry.weak import weak_visibility, weak_visibility_many

    calls: list = []
    from geometry._sweep import births as BI

    orig = SH.weak_visibility

    def record(env, ring, wanted, eps=0.0, grazing=None):
        calls.append((env, ring, wanted, eps, grazing))
        return orig(env, ring, wanted, eps, grazing)

    monkeypatch.setattr(SH, "weak_visibility", record)  # the samples and the corners
    monkeypatch.setattr(BI, "weak_visibility", record)  # the eroded targets
    monkeypatch.setattr(S.Sweeper, "_prefetch", lambda self, qs, eroded=(): None)  # one by one here
    lab = Scene.load("sensorplan_gym/scenes/lab.json")
    partial_region(lab, target_in="goal", theta=0.0)
    recognizable_region(Scene.load("sensorplan_gym/scenes/lab.json"), model="partial", theta=0.0)
    groups: dict = {}
    for c in calls:
        groups.setdefault((id(c[0]), c[3], id(c[4])), []).append(c)
    cases = [
        (cs[0][0], [c[1] for c in cs], [c[2] for c in cs], cs[0][3], cs[0][4])
        for cs in groups.values()
    ]
    assert len(cases) >= 2 and sum(len(c[1]) for c in cases) > 20
    # unwanted pieces (paper 5.2): the same targets with every other edge unwanted
    env, rings, _, eps, grazing = cases[0]
    half = [np.arange(len(r)) % 2 == 0 for r in rings]
    cases.append((env, rings, half, eps, grazing))
    for seed in range(100000, 100012):
        d = fuzz_scene(seed, contacts=True)
        if d is None:
            continue
        s = Scene.from_dict({k: v for k, v in d.items() if k != "features"})
        pts = np.asarray(shapely.get_coordinates(s.goal_geom))[:4]
        rings = [
            ccw_ring(s.target_at(x, y, th), clockwise=True) for x, y in pts for th in (0.0, 0.7)
        ]
        ones = [np.ones(len(r), dtype=bool) for r in rings]
        cases += [(scene_domain(s), rings, ones, eps, None) for eps in (0.0, 0.05)]
    n = 0
    for env, rings, wanted, eps, grazing in cases:
        many = weak_visibility_many(env, rings, wanted, eps, grazing)
        for r, w, got in zip(rings, wanted, many, strict=True):
            want = weak_visibility(env, r, w, eps, grazing)
            assert shapely.equals_exact(got, want, 0.0), (got, want)
            n += 1
    assert n > 100


def test_a_repeated_sweep_is_reused_on_the_same_scene_only(monkeypatch):
    """The swept partial region with and without ``conservative`` and the 5.2 region after
    it run their sweeps once per scene object (``partial._SWEEPS``); the answers equal
    those of a freshly loaded scene, and another scene object sweeps anew."""
    from geometry import partial as P

    calls = []
    orig = P.swept_shadows

    def counted(*a, **k):
        calls.append(1)
        return orig(*a, **k)

    monkeypatch.setattr(P, "swept_shadows", counted)
    s = Scene.load("sensorplan_gym/scenes/lab.json")
    a = partial_region(s, target_in="goal", theta=0.0)
    b = partial_region(s, target_in="goal", theta=0.0, conservative=True)
    assert len(calls) == 1
    assert b.area < a.area and shapely.difference(b, a).area < 1e-12
    fresh = Scene.load("sensorplan_gym/scenes/lab.json")
    assert shapely.to_wkb(partial_region(fresh, target_in="goal", theta=0.0)) == shapely.to_wkb(a)
    assert len(calls) == 2  # another scene object: no reuse
    c = recognizable_region(s, model="partial", theta=0.0)
    d = recognizable_region(s, model="partial", theta=0.0, conservative=True)
    assert len(calls) == 4  # the 5.2 sweeps of G and H, each once
    assert shapely.difference(d, c).area < 1e-12
    # a progress callback sees every edge swept: no reuse then
    seen = []
    partial_region(s, target_in="goal", theta=0.0, progress=lambda i, n: seen.append(i))
    assert len(calls) == 5 and seen


def test_lazy_bisection_stops_once_the_ends_stand_still(monkeypatch) -> None:
    """With the lazy rules an edge leaves the bisection once its ends move by at most tol / 4
    between the last time found valid and the first found not: the bracket it returns still
    holds the death (valid at t_ok, not at t_bad, or t_ok the start), is never wider than the
    full bisection's first bracket that contains it, and either the ends stand still over
    it or it is as narrow as all the steps make it."""
    sw = _sweeper(monkeypatch)
    early = 0
    for q0, dq, edges in _moving_edges(sw):
        zero, one = np.zeros(len(edges)), np.ones(len(edges))
        sw.lazy_samples = False
        full_ok, full_bad = sw._bisect(edges, zero, one, q0, dq)
        sw.lazy_samples = True
        t_ok, t_bad = sw._bisect(edges, zero, one, q0, dq)
        assert ((t_ok <= full_ok) & (full_bad <= t_bad)).all()
        a, b = sw._ends_many(edges, np.stack([t_ok, t_bad], axis=1), q0, dq)
        still = sw._past_death(a[:, :1], b[:, :1], a[:, 1:], b[:, 1:])
        narrow = (t_bad - t_ok) <= 2.0**-sw.bisect_steps
        assert (still | narrow).all()
        early += int((~narrow).sum())
    assert early > 0  # not vacuous: some edges leave the bisection early


def _drop_short_definition(v: np.ndarray, length: float) -> list[int]:
    """The vertices :func:`geometry._sweep.shadow._drop_short` keeps, one by one: vertex i when it
    lies at least ``length`` (max-norm) from the last kept vertex."""
    keep = [0]
    for i in range(1, len(v)):
        if np.abs(v[i] - v[keep[-1]]).max() >= length:
            keep.append(i)
    return keep


def test_drop_short_keeps_the_vertices_of_its_definition() -> None:
    """The run-skipping scan of ``_drop_short`` keeps the vertices of the one-by-one
    definition (then closes the ring and moves each kept vertex to its cluster's corner as
    before): bit for bit on 5,000 random rings, a third of their steps short."""
    rng = np.random.default_rng(7)
    length = 1e-2
    clustered = 0
    for _ in range(5000):
        n = int(rng.integers(1, 30))
        steps = rng.normal(size=(n, 2)) * np.where(rng.random((n, 1)) < 0.35, 1e-3, 1.0)
        v = np.cumsum(steps, axis=0)
        keep = _drop_short_definition(v, length)
        tail = len(v)
        while len(keep) > 1 and np.abs(v[keep[-1]] - v[0]).max() < length:
            tail = keep.pop()
        want = v if len(keep) == len(v) else SH._corners(v, keep, tail, length)
        got = SH._drop_short(v, length)
        assert got.shape == want.shape and np.array_equal(got, want)
        clustered += len(keep) < len(v)
    assert clustered > 1000  # not vacuous: most rings have clusters


@pytest.mark.parametrize("name", ["sensorplan_gym/scenes/lab.json", "real/heidelberg_l1"])
def test_corners_that_see_k_are_those_inside_its_weak_visibility_region(name, monkeypatch) -> None:
    """``Sweeper._anchors`` (lazy rules) takes the corners whose rays towards K reach it
    (``weak.corners_seeing``) instead of the corners within 1e-6 of K's weak visibility
    region (the previous rules): none outside that region, and the ones it leaves out lie on
    the region's boundary (a ray grazing them, no positive angle of K in sight); the
    sweep's shadows with either mask are the same (above)."""
    from sensorplan_gym.core.scenes import load_scene

    scene = Scene.load(name) if name.endswith(".json") else load_scene(name)
    sw = _sweeper(monkeypatch, scene)
    new = sw._anchors()
    del sw._anchor_mask
    sw.lazy_samples = False
    old = sw._anchors()
    assert new.sum() > 0 and not (new & ~old).any()
    ring = sw.hull[::-1]
    seen = shapely.union(
        SH.weak_visibility(sw.env, ring, np.ones(len(ring), dtype=bool)), sw._hull_poly
    )
    left = shapely.points(sw.env.vert[old & ~new])
    assert (shapely.distance(seen.boundary, left) <= 1e-6 * sw.env.scale).all()


def _batches(monkeypatch, name: str, scene: Scene, rec: bool) -> list:
    """Every call of the batched ``name`` method (its sweeper, arguments, answer) during the
    swept partial query over G (``rec``: the 5.2 query) on ``scene``."""
    calls = []
    orig = getattr(S.Sweeper, name)

    def spy(self, groups):
        out = orig(self, groups)
        calls.append((self, groups, out))
        return out

    monkeypatch.setattr(S.Sweeper, name, spy)
    if rec:
        recognizable_region(scene, model="partial", theta=0.0)
    else:
        partial_region(scene, target_in="goal", theta=0.0)
    monkeypatch.setattr(S.Sweeper, name, orig)
    return calls


def _same_trace(a: tuple, b: tuple) -> bool:
    """Two answers of _trace_many, bit for bit: the quads' WKB and the end times."""
    return [shapely.to_wkb(q) for q in a[0]] == [shapely.to_wkb(q) for q in b[0]] and a[1] == b[1]


@pytest.mark.parametrize(("scene", "rec"), [("slow_2", False), ("slow_1", False), ("lab", True)])
def test_batched_traces_and_grids_equal_group_by_group(monkeypatch, scene, rec) -> None:
    """_trace_groups and _grid_many give each group of a batch (intervals of several
    segments of G, both directions) bit for bit what it gets alone: the rows of a batch
    carry their own sweep and grid."""

    def load() -> Scene:  # a fresh scene per query (a scene keeps its sweeps)
        if scene == "lab":
            return Scene.load("sensorplan_gym/scenes/lab.json")
        return Scene.from_dict(json.loads((REPRO / f"{scene}.json").read_text())["scene"])

    traces = _batches(monkeypatch, "_trace_groups", load(), rec)
    grids = _batches(monkeypatch, "_grid_many", load(), rec)
    # not vacuous: batches of several groups, with traced edges among them
    multi = [c for c in traces if len([g for g in c[1] if g[0]]) > 1]
    assert multi and any(sum(len(q) for q, _ in c[2]) for c in multi)
    assert any(len(c[1]) > 1 for c in grids)
    for sw, groups, out in multi:
        for grp, got in zip(groups, out, strict=True):
            assert _same_trace(got, sw._trace_many(*grp))
    for sw, groups, out in grids:
        if len(groups) < 2:
            continue
        for grp, got in zip(groups, out, strict=True):
            alone = sw._grid(*grp)
            assert all(
                np.array_equal(x, y, equal_nan=True) for x, y in zip(got, alone, strict=True)
            )


def test_vertex_cells_by_sorting_equal_the_dictionary(monkeypatch) -> None:
    """_vertex_cell (sorted complex keys) finds the vertex a dictionary of the rounded
    coordinates finds (the last of equal cells), on the vertices themselves, on points
    moved within and across a cell, on duplicated vertices and on points far away."""
    sw = _sweeper(monkeypatch)
    g = sw.shadow_grid
    env = sw.env.vert
    cells = np.round(env / g)
    table = {(float(x), float(y)): i for i, (x, y) in enumerate(cells.tolist())}
    rng = np.random.default_rng(5)
    pts = np.vstack(
        [
            env,
            env + rng.uniform(-0.4, 0.4, size=env.shape) * g,  # the same cell
            env + rng.choice([-2.0, 2.0], size=env.shape) * g,  # a neighbouring cell
            rng.uniform(-1e3, 1e3, size=(50, 2)),
            -0.0 * env[:3],
        ]
    )
    ref = [table.get((x, y), -1) for x, y in np.round(pts / g).tolist()]
    got = sw._vertex_cell(pts)
    assert got.tolist() == ref
    assert (got[: len(env)] >= 0).all() and (got[2 * len(env) : 3 * len(env)] < 0).any()
    # duplicated vertices: the last one, as the dictionary keeps it
    dup = np.vstack([env, env[:5], env[2:4]])
    fake = SimpleNamespace(env=SimpleNamespace(vert=dup), shadow_grid=g)
    table = {(float(x), float(y)): i for i, (x, y) in enumerate(np.round(dup / g).tolist())}
    ref = [table.get((x, y), -1) for x, y in np.round(pts / g).tolist()]
    assert S.Sweeper._vertex_cell(fake, pts).tolist() == ref
