"""The batched simulation core: N sensor robots (each in its own world, with its own random
stream) held in arrays and advanced by one vectorised call.

:class:`BatchSim` owns the state every task shares -- the world of each sub-environment
(copied into padded rows at its reset), the robot poses, the executed sensor poses and the
latest scans -- and the mechanics:

* :meth:`BatchSim.drive` -- translate in the robot frame, swept against walls, obstacles and
  (Recognize) the target, then turn; the sweep runs only for robots whose conservative
  clearance is below the step;
* :meth:`BatchSim.sense` -- perturb the commanded sensor poses within ``eps_pos``/``eps_aim``
  and cast every beam of every robot in one pass (:func:`.sensor.cast_batch`);
* :meth:`BatchSim.query` -- exact recognizability (shapely ``contains_xy`` on the exact
  region, the aim check) and the distance to the region.

The tasks (``sensorplan_gym.envs``) subclass it with their reset and reward rules; the
single env is the batch of one and the vector env the batch of N, so both run this code.

Two paths compute the same numbers: with numba (``fused = True``) :meth:`sense`,
:meth:`query`, the observation and the tasks' whole steps are compiled kernels
(:mod:`.fused`) over preallocated arrays -- the per-row state lives in a few stacked arrays
(``P`` poses, ``C`` constants, ``I8`` integer task state, with the named attributes as
views) so that one call carries it all; without numba (or ``fused = False``) the numpy
code below runs.  Both evaluate the same expressions in the same order and use libm's
transcendentals (:func:`.kernels.libm`), so their answers are bitwise equal.

Worlds enter rows through :meth:`load_world`, or :meth:`load_worlds` for many rows at once
(resets on scene pools): a world seen before is copied from a snapshot of the rows it wrote
the first time, one array operation per padded array for all the resetting rows.

Randomness
----------
Sub-environment ``i`` draws only from its own ``numpy`` generator ``rngs[i]``: directly at its
resets (scene, random start), through a block of pre-drawn uniforms for hiding Recognize's
target (:mod:`.targets`) and, for the per-step sensor uncertainty and noise, through a
block of pre-drawn uniforms and normals refilled from that generator every
:data:`BLOCK` readings (just before the reading that needs it, in both paths).  A
sub-environment of a batch therefore produces exactly the numbers a single environment
seeded the same way produces.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from gymnasium.utils import seeding

from . import fused
from .collision import sweep_batch
from .kernels import HAVE_NUMBA, cast, libm
from .queries import aim_ok_batch, in_region_batch, region_distance_batch
from .segments import PAD, SegmentRows
from .sensor import add_noise, beam_offsets
from .world import World, field_lookup

__all__ = ["BLOCK", "BatchSim"]

#: steps of pre-drawn per-step random numbers per refill
BLOCK = 64
TWO_PI = 2 * math.pi


class BatchSim:
    """State and mechanics of ``n`` sub-environments (see the module docstring).

    Arrays (``N`` = ``n``): ``x, y, psi`` commanded poses (world frame, radians);
    ``sx, sy, spsi`` executed sensor poses; ``scan_dist (N, B)``, ``scan_normal (N, B, 2)``,
    ``scan_hit (N, B)``, ``scan_ang (N, B)`` the latest readings; ``worlds[i]`` the
    :class:`World` of sub-environment ``i``.
    """

    def __init__(self, n: int, n_beams: int, noise: float, robot_radius: float) -> None:
        self.n = int(n)
        self.n_beams = int(n_beams)
        self.noise = float(noise)
        self.robot_radius = float(robot_radius)
        N, B = self.n, self.n_beams
        self.worlds: list[World | None] = [None] * N
        self.rngs: list[np.random.Generator] = [seeding.np_random(None)[0] for _ in range(N)]
        self._U = np.zeros((N, BLOCK, 3))
        self._Z = np.zeros((N, BLOCK, B))
        self._ptr = np.full(N, BLOCK)
        self._empty: set[int] = set()  # stochastic rows whose pre-drawn block is used up
        #: commanded poses x, y, psi and executed sensor poses sx, sy, spsi (views of P)
        self.P = np.zeros((6, N))
        #: per-row constants (views of C): see :data:`.fused.C_NAMES`
        self.C = np.ones((len(fused.C_NAMES), N))
        #: int64 task state (views of I8): elapsed steps, then the task's own
        self.I8 = np.zeros((5, N), dtype=np.int64)
        self._views()
        self.scan_dist = np.zeros((N, B))
        self.scan_normal = np.zeros((N, B, 2))
        self.scan_hit = np.zeros((N, B), dtype=bool)
        self.scan_ang = np.zeros((N, B))
        self.has_scan = np.zeros(N, dtype=bool)
        self.segs = SegmentRows(N)  # walls, obstacles (and the target in Recognize)
        self.static_segs = SegmentRows(N)  # walls and obstacles: the map
        self.map_ranges = getattr(self, "map_ranges", False)
        self.map_dist = np.zeros((N, B))
        self.region_segs = SegmentRows(N)
        #: the exact region's boundary segments ``(4, N, S)``: start x, y, end x, y (padding
        #: at :data:`.segments.PAD`), for :func:`.fused.point_in_region`
        self.region_xy = np.full((4, N, 1), PAD)
        self.space_xy = np.full((4, N, 1), PAD)  # the robot's free space, likewise
        self.regions = np.empty(N, dtype=object)
        self.spaces = np.empty(N, dtype=object)  # free space of the robot's centre
        self.hulls = np.zeros((N, 2, 1, 2))
        self.centers = np.zeros((N, 2, 2))
        self.fields = np.zeros((N, 1, 1))
        self.field_o = np.zeros((N, 2))
        self.field_inv_h = np.ones(N)
        self.lo, self.hi = np.zeros((N, 2)), np.ones((N, 2))
        self.goal_c, self.fail_c = np.zeros((N, 2)), np.zeros((N, 2))
        #: beam offsets relative to the aim: their cosines, sines and the angles (radians)
        self.OFF = np.zeros((3, N, B))
        self.offsets = self.OFF[2]
        self.obs_consts = np.zeros((N, 10))
        self.stochastic = np.zeros(N, dtype=bool)
        self.n_stochastic = 0  # rows whose readings draw random numbers
        self.aim_trivial = np.zeros(N, dtype=bool)
        #: float64 parameters of the compiled kernels (:data:`.fused.P_NOISE`, ...)
        self.params = np.zeros(fused.N_PARAMS)
        self.params[fused.P_NOISE] = self.noise
        #: run the compiled kernels (numba installed); ``False`` forces the numpy path
        self.fused = fused.FUSED
        self._one_world = False
        self._kbuf = _Buffers(N)
        self._kargs: tuple | None = None  # the compiled step's arguments (tasks build them)

    #: names of the rows of ``I8`` (tasks extend it; at most 5)
    I8_NAMES: tuple[str, ...] = ("elapsed",)

    @property
    def _field_used(self) -> bool:
        """Whether the drive reads the clearance fields (disc robots, or no numba)."""
        return self.robot_radius > 0.0 or not HAVE_NUMBA

    def _views(self) -> None:
        for k, name in enumerate(("x", "y", "psi", "sx", "sy", "spsi")):
            setattr(self, name, self.P[k])
        for k, name in enumerate(fused.C_NAMES):
            setattr(self, name, self.C[k])
        for k, name in enumerate(self.I8_NAMES):
            setattr(self, name, self.I8[k])

    # ---- randomness -------------------------------------------------------------------
    def seed_env(self, i: int, seed: int | None) -> None:
        """Re-seed sub-environment ``i`` (``seed=None``: fresh OS entropy) and drop its
        pre-drawn block."""
        self.rngs[i] = seeding.np_random(seed)[0]
        self.drop_block(i)

    def drop_block(self, i: int) -> None:
        """Forget sub-environment ``i``'s pre-drawn blocks (its generator was replaced)."""
        self._ptr[i] = BLOCK
        if self.stochastic[i]:
            self._empty.add(i)

    def _refill(self, idx: np.ndarray) -> None:
        """Refill the pre-drawn blocks of the stochastic rows of ``idx`` that are used up,
        each from its own generator (what their next sensor reading needs first)."""
        if not self._empty:
            return
        todo = (
            self._empty.intersection(idx.tolist())
            if len(idx) > 1
            else ({int(idx[0])} & self._empty)
        )
        for i in sorted(todo):
            rng = self.rngs[i]
            self._U[i] = rng.random((BLOCK, 3))
            self._Z[i] = rng.standard_normal((BLOCK, self.n_beams))
            self._ptr[i] = 0
            self._empty.discard(i)

    def _note_used(self, idx: np.ndarray) -> None:
        """Record the stochastic rows of ``idx`` whose block the last readings used up."""
        p = self._ptr[idx]
        if (p >= BLOCK).any():
            self._empty.update(idx[(p >= BLOCK) & self.stochastic[idx]].tolist())

    def _draws(self, idx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The next per-step draws of sub-environments ``idx``: uniforms ``(k, 3)`` and
        standard normals ``(k, B)``."""
        self._refill(idx)
        p = self._ptr[idx]
        self._ptr[idx] += 1
        self._note_used(idx)
        return self._U[idx, p], self._Z[idx, p]

    # ---- worlds -----------------------------------------------------------------------
    def _grow(self, name: str, shape: tuple[int, ...], edge: bool = False) -> np.ndarray:
        """The per-row array ``name``, enlarged (rows kept) to hold ``shape`` per row; the new
        cells are zero, or (``edge``) copies of each row's last cell along every axis."""
        a = getattr(self, name)
        want = tuple(int(v) for v in np.maximum(shape, a.shape[1:]))
        if want != a.shape[1:]:
            pad = [(0, 0)] + [(0, w - h) for w, h in zip(want, a.shape[1:], strict=True)]
            a = np.pad(a, pad, mode="edge" if edge else "constant")
            setattr(self, name, a)
        return a

    def load_world(self, i: int, world: World, max_speed: float | None = None) -> None:
        """Copy ``world`` into row ``i`` (a no-op when it is already there)."""
        if self.worlds[i] is world:
            return
        self.worlds[i] = world
        self._kargs = None  # arrays may grow
        r = world.batch_rows()
        self.segs.set_row(i, r["segs"])
        self.static_segs.set_row(i, r["segs"])
        self.region_segs.set_row(i, r["region_segs"])
        self._set_ring_row("region_xy", i, r["region_xy"])
        self._set_ring_row("space_xy", i, r["space_xy"])
        self.regions[i] = world.region
        self.spaces[i] = world.robot_space
        k = r["hulls"].shape[1]
        hulls = self._grow("hulls", (2, k, 2), edge=True)
        hulls[i, :, :k] = r["hulls"]
        hulls[i, :, k:] = r["hulls"][:, -1:]
        self.centers[i] = r["centers"]
        F, ox, oy, inv_h = r["field"]
        if self._field_used:
            fields = self._grow("fields", F.shape)
            fields[i] = 0.0
            fields[i, : F.shape[0], : F.shape[1]] = F
        self.field_o[i] = (ox, oy)
        self.field_inv_h[i] = inv_h
        self.diameter[i] = world.diameter
        self.reach[i] = world.reach
        self.skin[i] = world.skin
        self.eps_pos[i] = world.eps_pos
        self.eps_aim[i] = world.eps_aim
        self.fov[i] = world.fov
        self.max_range[i] = world.max_range
        self.max_speed[i] = 0.03 * world.diameter if max_speed is None else max_speed
        self.lo[i], self.hi[i] = world.lo, world.hi
        self.goal_c[i], self.fail_c[i] = world.goal_center, world.failure_center
        off = beam_offsets(self.n_beams, world.fov)
        self.OFF[:, i] = (np.cos(off), np.sin(off), off)
        span = world.hi - world.lo
        self.obs_consts[i] = (
            *world.lo,
            2.0 / span[0],
            2.0 / span[1],
            1.0 / world.diameter,
            1.0 / world.reach,
            *world.goal_center,
            *world.failure_center,
        )
        st = world.eps_pos > 0 or world.eps_aim > 0 or self.noise > 0
        self.n_stochastic += int(st) - int(self.stochastic[i])
        self.stochastic[i] = st
        self._empty.discard(i)
        if self.stochastic[i] and self._ptr[i] >= BLOCK:
            self._empty.add(i)
        self.aim_trivial[i] = world.fov >= TWO_PI - 1e-12 and math.isinf(world.max_range)
        self._one_world = all(w is world for w in self.worlds)

    # ---- many rows at once: per-world snapshots ---------------------------------------
    def _row_arrays(self) -> list[tuple[np.ndarray, int]]:
        """The padded arrays :meth:`load_world` writes, with their row axis (tasks extend
        the list)."""
        return [
            (self.segs.data, 1),
            (self.static_segs.data, 1),
            (self.region_segs.data, 1),
            (self.region_xy, 1),
            (self.space_xy, 1),
            (self.hulls, 0),
            (self.centers, 0),
            *([(self.fields, 0)] if self._field_used else []),
            (self.field_o, 0),
            (self.field_inv_h, 0),
            (self.C, 1),
            (self.lo, 0),
            (self.hi, 0),
            (self.goal_c, 0),
            (self.fail_c, 0),
            (self.OFF, 1),
            (self.obs_consts, 0),
            (self.stochastic, 0),
            (self.aim_trivial, 0),
        ]

    def load_worlds(self, rows: np.ndarray, worlds: list[World]) -> None:
        """Load ``worlds[k]`` into row ``rows[k]`` (as :meth:`load_world`).  A world seen
        before is copied from its snapshot -- the rows it wrote the first time -- with one
        array operation per padded array for all such rows; the snapshots are dropped when
        a larger world widens the arrays."""
        cache = self.__dict__.setdefault("_snap", _Snapshots())
        pending = [(i, w) for i, w in zip(rows.tolist(), worlds, strict=True)]
        while True:
            todo = [(i, w) for i, w in pending if self.worlds[i] is not w]
            if not todo:
                return
            arrays = self._row_arrays()
            cache.check(arrays)
            missing = [(i, w) for i, w in todo if id(w) not in cache.slot]
            if not missing:
                break
            seen: set[int] = set()
            for i, w in missing:  # the first row of each new world the slow way
                if id(w) in seen:
                    continue
                seen.add(id(w))
                self.load_world(i, w)
                arrays = self._row_arrays()
                cache.check(arrays)  # a wider world drops every snapshot: another round
                cache.add(w, i, arrays)
        fast_rows = [i for i, _ in todo]
        fast_slots = [cache.slot[id(w)] for _, w in todo]
        for i, w in todo:
            self.worlds[i] = w
        r = np.array(fast_rows)
        st = int(self.stochastic[r].sum())
        cache.copy(r, np.array(fast_slots), arrays)
        self._kargs = None
        for i in fast_rows:
            w = self.worlds[i]
            self.regions[i] = w.region
            self.spaces[i] = w.robot_space
        self.n_stochastic += int(self.stochastic[r].sum()) - st
        self._empty.difference_update(fast_rows)
        self._empty.update(r[self.stochastic[r] & (self._ptr[r] >= BLOCK)].tolist())
        w0 = self.worlds[0]
        self._one_world = all(w is w0 for w in self.worlds)
        self._rows_loaded(r)

    def _rows_loaded(self, rows: np.ndarray) -> None:
        """Task hook: rows ``rows`` got new worlds from snapshots."""

    def _set_ring_row(self, name: str, i: int, rows: np.ndarray) -> None:
        """Row ``i`` of the boundary array ``name`` ``(4, N, S)`` := ``rows`` ``(4, k)``,
        padded with :data:`.segments.PAD` (grown when ``k > S``)."""
        a = getattr(self, name)
        k = rows.shape[1]
        if k > a.shape[2]:
            a = np.concatenate([a, np.full((4, self.n, k - a.shape[2]), PAD)], axis=2)
            setattr(self, name, a)
        a[:, i, :k] = rows
        a[:, i, k:] = PAD

    def set_segments(self, i: int, rows: np.ndarray) -> None:
        """Row ``i`` of the sensed/collided segments := ``rows`` ``(6, k)``."""
        if rows.shape[1] > self.segs.m:
            self._kargs = None  # the rows grow
        self.segs.set_row(i, rows)

    # ---- mechanics --------------------------------------------------------------------
    def drive(self, act: np.ndarray, idx: np.ndarray, max_turn: float) -> np.ndarray:
        """Move sub-environments ``idx`` by actions ``act`` ``(k, >=3)`` in [-1, 1]
        (forward, lateral, turn; see ``RobotEnv``).  Returns ``collided (k,)``."""
        sel = self.sel(idx)
        x, y, psi = self.x[sel], self.y[sel], self.psi[sel]
        c, s = libm(math.cos, psi), libm(math.sin, psi)
        v = self.max_speed[sel]
        a0, a1 = act[:, 0], act[:, 1]
        dx = v * (c * a0 - s * a1)
        dy = v * (s * a0 + c * a1)
        if self.robot_radius == 0.0 and HAVE_NUMBA:
            # a point robot: the compiled sweep is cheaper than deciding where to skip it
            t = sweep_batch(x, y, dx, dy, self._rows(self.segs, idx), 0.0, self.skin[sel])
        else:
            t = self._sweep_near(idx, sel, x, y, dx, dy)
        self.x[sel] = x + t * dx
        self.y[sel] = y + t * dy
        self.psi[sel] = (psi + max_turn * act[:, 2] + math.pi) % TWO_PI - math.pi
        return t < 1.0

    def _sweep_near(self, idx, sel, x, y, dx, dy) -> np.ndarray:
        """The sweep, run only where a wall, an obstacle or the target may be within reach
        (the conservative clearance field says where; the answers are the same)."""
        need = np.hypot(dx, dy) + self.robot_radius + 2 * self.skin[sel]
        clear = field_lookup(
            self.fields,
            self.field_o[sel, 0],
            self.field_o[sel, 1],
            self.field_inv_h[sel],
            x,
            y,
            rows=idx,
        )
        clear = np.minimum(clear, self._extra_clearance(idx, x, y, clear > need))
        t = np.ones(len(idx))
        close = clear <= need
        if close.any():
            j = idx[close]
            t[close] = sweep_batch(
                x[close],
                y[close],
                dx[close],
                dy[close],
                self._rows(self.segs, j),
                self.robot_radius,
                self.skin[j],
            )
        return t

    def _extra_clearance(self, idx, x, y, mask) -> np.ndarray:
        """Distance to segments that the clearance field does not know (the target in
        Recognize), where ``mask``; ``inf`` elsewhere.  Overridden by tasks."""
        return np.full(len(idx), np.inf)

    @staticmethod
    def _rows(rows: SegmentRows, j: np.ndarray):
        return _Rows(rows, j)

    def sense(self, idx: np.ndarray) -> None:
        """Read the sensors of sub-environments ``idx`` from their executed poses (the
        commanded pose displaced uniformly within ``eps_pos`` -- cut short at walls -- and
        turned uniformly within ``eps_aim``), with range noise."""
        if self.fused:
            self._refill(idx)
            used = fused.sense_kernel(
                idx,
                self.P,
                self.C,
                self.stochastic,
                self.params,
                self.OFF,
                self.segs.data,
                self.static_segs.data,
                self._U,
                self._Z,
                self._ptr,
                self.scan_dist,
                self.scan_normal,
                self.scan_hit,
                self.scan_ang,
                self.map_dist,
                self.has_scan,
            )
            if used:
                self._note_used(idx)
            return
        self._sense_numpy(idx)

    def _sense_numpy(self, idx: np.ndarray) -> None:
        sel = self.sel(idx)
        x, y, psi = self.x[sel], self.y[sel], self.psi[sel]
        st = self.stochastic[sel]
        z = None
        if st.any():
            j = idx[st]
            U, Z = self._draws(j)
            z = np.zeros((len(idx), self.n_beams))
            z[st] = Z
            ep, ea = self.eps_pos[j], self.eps_aim[j]
            r = ep * np.sqrt(U[:, 0])
            phi = -math.pi + TWO_PI * U[:, 1]
            ddx, ddy = r * libm(math.cos, phi), r * libm(math.sin, phi)
            pos = ep > 0
            sx, sy, sp = x[st], y[st], psi[st]
            if pos.any():
                k = j[pos]
                t = sweep_batch(
                    sx[pos],
                    sy[pos],
                    ddx[pos],
                    ddy[pos],
                    self._rows(self.segs, k),
                    0.0,
                    self.skin[k],
                )
                sx[pos] = sx[pos] + t * ddx[pos]
                sy[pos] = sy[pos] + t * ddy[pos]
            sp = np.where(ea > 0, sp + (-ea + 2 * ea * U[:, 2]), sp)
            x, y, psi = x.copy(), y.copy(), psi.copy()
            x[st], y[st], psi[st] = sx, sy, sp
        reach = self.reach[sel]
        # world edges are oriented into the free space and the target's outwards: cull
        dist, nrm, hit = self._cast(idx, sel, self.segs, x, y, psi, reach)
        if z is not None and self.noise > 0:
            dist = add_noise(dist, hit, z, self.noise, reach)
        if self.map_ranges:  # what the map predicts from the commanded pose
            cx, cy, cp = self.x[sel], self.y[sel], self.psi[sel]
            self.map_dist[sel] = self._cast(idx, sel, self.static_segs, cx, cy, cp, reach)[0]
        self.sx[sel], self.sy[sel], self.spsi[sel] = x, y, psi
        self.scan_dist[sel] = dist
        self.scan_normal[sel] = nrm
        self.scan_hit[sel] = hit
        self.scan_ang[sel] = self.offsets[sel] + psi[:, None]
        self.has_scan[sel] = True

    def _cast(self, idx, sel, segs: SegmentRows, x, y, psi, reach):
        """The culled cast of the fans of rows ``idx`` from ``(x, y)`` aimed at ``psi``:
        ``(dist, normal, hit)`` as :func:`.sensor.cast_batch`.  Beam directions are the
        offsets' unit vectors turned by ``psi`` (as the compiled kernel computes them)."""
        c, s = libm(math.cos, psi)[:, None], libm(math.sin, psi)[:, None]
        co, so = self.OFF[0][sel], self.OFF[1][sel]
        rows = self._rows(segs, idx)
        seg = (rows.x0, rows.y0, rows.ex, rows.ey, rows.nx, rows.ny)
        dist, hit, gx, gy = cast(x, y, co * c - so * s, so * c + co * s, *seg, reach, True)
        nrm = np.empty((*dist.shape, 2))
        nrm[..., 0] = gx
        nrm[..., 1] = gy
        return dist, nrm, hit

    def query(
        self, idx: np.ndarray, x: np.ndarray | None = None, y=None, psi=None
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(recognizing, in_region, aim_ok, distance_to_region)`` ``(k,)`` for the poses
        of sub-environments ``idx`` (or the given poses): placement in the exact
        recognizable region and aim OK; Euclidean distance (0 inside, ``inf`` if the region
        is empty)."""
        sel = self.sel(idx)
        if x is None:
            x, y, psi = self.x[sel], self.y[sel], self.psi[sel]
        if self.fused:
            k = len(idx)
            rec = np.empty(k, dtype=bool)
            inside = np.empty(k, dtype=bool)
            aim = np.empty(k, dtype=bool)
            dist = np.empty(k)
            fused.query_kernel(
                idx,
                np.ascontiguousarray(x, dtype=np.float64),
                np.ascontiguousarray(y, dtype=np.float64),
                np.ascontiguousarray(psi, dtype=np.float64),
                self.C,
                self.aim_trivial,
                self.region_xy,
                self.region_segs.data,
                self.hulls,
                self.centers,
                rec,
                inside,
                aim,
                dist,
            )
            return rec, inside, aim, dist
        regions = self.regions[sel]
        first = regions[0]
        if self._one_world and len(regions) > 1:
            inside = in_region_batch(first, x, y)  # one prepared geometry: a faster path
        else:
            inside = in_region_batch(regions, x, y)
        if self.aim_trivial[sel].all():
            aim = np.ones(len(x), dtype=bool)
        else:
            aim = aim_ok_batch(
                x,
                y,
                psi,
                self.hulls[sel],
                self.centers[sel],
                fov=self.fov[sel],
                eps_aim=self.eps_aim[sel],
                eps_pos=self.eps_pos[sel],
                max_range=self.max_range[sel],
            )
        dist = region_distance_batch(self._rows(self.region_segs, idx), x, y, inside)
        return inside & aim, inside, aim, dist

    def in_free_space(self, idx: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """``(k,)`` bool: ``(x, y)`` is a free position of sub-environment ``idx``'s robot."""
        if self.fused:
            out = np.empty(len(idx), dtype=bool)
            xs = np.ascontiguousarray(x, dtype=np.float64)
            ys = np.ascontiguousarray(y, dtype=np.float64)
            fused.region_test(xs, ys, self.space_xy, idx, out)
            return out
        spaces = self.spaces[self.sel(idx)]
        if self._one_world and len(spaces) > 1:
            return in_region_batch(spaces[0], x, y)
        return in_region_batch(spaces, x, y)

    def sel(self, idx: np.ndarray) -> slice | np.ndarray:
        """An index for sub-environments ``idx`` (sorted, distinct): a slice (views, no
        copies) when they are all of them."""
        return _ALL if len(idx) == self.n else idx

    # ---- one sub-environment, for single envs, oracles and rendering -------------------
    def pose(self, i: int) -> tuple[float, float, float]:
        return (float(self.x[i]), float(self.y[i]), float(self.psi[i]))

    def sensor_pose(self, i: int) -> tuple[float, float, float]:
        return (float(self.sx[i]), float(self.sy[i]), float(self.spsi[i]))

    def scan(self, i: int) -> tuple[np.ndarray, ...] | None:
        """``(dist, normal, hit, angles)`` of sub-environment ``i`` (copies) or ``None``."""
        if not self.has_scan[i]:
            return None
        return (
            self.scan_dist[i].copy(),
            self.scan_normal[i].copy(),
            self.scan_hit[i].copy(),
            self.scan_ang[i].copy(),
        )

    def __getstate__(self) -> dict[str, Any]:
        state = self.__dict__.copy()
        state.pop("_snap", None)  # keyed by object ids: rebuilt after unpickling
        state["_kargs"] = None
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        import shapely

        self.__dict__.update(state)
        self._views()  # pickling does not keep views
        self._kargs = None
        self.offsets = self.OFF[2]
        for g in (*self.regions, *self.spaces):
            if g is not None:
                shapely.prepare(g)


_ALL = slice(None)


class _Snapshots:
    """Per-world copies of the rows a world writes into the padded arrays (slot ``k`` of
    every array holds the row of the ``k``-th world seen)."""

    def __init__(self) -> None:
        self.slot: dict[int, int] = {}
        self.keep: list = []  # the worlds (their ids stay valid)
        self.store: list[np.ndarray] = []
        self.shapes: tuple | None = None

    @staticmethod
    def _shapes(arrays) -> tuple:
        return tuple(a.shape[:ax] + a.shape[ax + 1 :] for a, ax in arrays)

    def check(self, arrays) -> None:
        """Drop every snapshot when the arrays' padded shapes changed."""
        sh = self._shapes(arrays)
        if sh != self.shapes:
            self.__init__()
            self.shapes = sh

    def add(self, world, i: int, arrays) -> None:
        k = len(self.keep)
        if not self.store:
            self.store = [
                np.zeros(a.shape[:ax] + (8,) + a.shape[ax + 1 :], dtype=a.dtype) for a, ax in arrays
            ]
        cap = self.store[0].shape[arrays[0][1]]
        if k == cap:
            self.store = [
                np.concatenate([s, np.zeros_like(s)], axis=ax)
                for s, (_, ax) in zip(self.store, arrays, strict=True)
            ]
        for s, (a, ax) in zip(self.store, arrays, strict=True):
            if ax == 0:
                s[k] = a[i]
            else:
                s[:, k] = a[:, i]
        self.slot[id(world)] = k
        self.keep.append(world)

    def copy(self, rows: np.ndarray, slots: np.ndarray, arrays) -> None:
        """Rows ``rows`` := snapshots ``slots``."""
        for s, (a, ax) in zip(self.store, arrays, strict=True):
            if ax == 0:
                a[rows] = s[slots]
            else:
                a[:, rows] = s[:, slots]


class _Buffers:
    """Preallocated outputs of the compiled step for a batch of ``n``."""

    def __init__(self, n: int) -> None:
        self.reward = np.zeros(n)
        self.flags = np.zeros((5, n), dtype=bool)
        self.dist = np.zeros(n)


class _Rows:
    """Rows ``j`` of a :class:`SegmentRows` (gathered once; all when ``j`` covers them)."""

    __slots__ = ("x0", "y0", "ex", "ey", "nx", "ny")

    def __init__(self, rows: SegmentRows, j: np.ndarray) -> None:
        d = rows.data if len(j) == rows.data.shape[1] else rows.data[:, j]
        self.x0, self.y0, self.ex, self.ey, self.nx, self.ny = d
