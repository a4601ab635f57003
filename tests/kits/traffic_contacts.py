"""Contact checks shared by the traffic tests: the ego's box, actor-actor / actor-ego /
actor-static overlaps and vehicle-person overlaps at one instant (world frame, metres).

The kit judges contact with its own geometry, not production's: footprints are computed here from
each box's centre, size and yaw, and two footprints touch when no axis separates them -- a
separating-axis test over every edge normal of both quads, for all pairs of a time step at once
in numpy after a broad phase by bounding circles. Touching edges count, and so does a gap below
:data:`SLACK_M` (a micrometre's thousandth): the test is never weaker than shapely's polygon
intersection, which ``tests/traffic/test_contact_kit.py`` holds it to on random boxes (touching
and near-miss pairs included). A wrong overlap test in :mod:`generator.geometry.boxes` therefore
cannot pass the simulation's tests; ``tests/geometry/test_boxes.py`` checks that both agree on many
random boxes.
"""

from __future__ import annotations

import numpy as np

EGO_SIZE_M = (4.6, 1.9, 1.5)
#: a gap narrower than this (metres) counts as contact: rounding can never hide a touch shapely sees
SLACK_M = 1e-9


class Box:
    """An upright box by centre (x, y, z), size (length, width, height) and yaw (radians)."""

    def __init__(self, center, size, yaw: float):
        self.center, self.size, self.yaw = tuple(center), tuple(size), float(yaw)


def footprint(box) -> np.ndarray:
    """(4, 2) corners of ``box``'s footprint (anything with ``center``, ``size`` and ``yaw``)."""
    c, s = np.cos(box.yaw), np.sin(box.yaw)
    hl, hw = box.size[0] / 2.0, box.size[1] / 2.0
    local = np.array([[-hl, -hw], [hl, -hw], [hl, hw], [-hl, hw]])
    return local @ np.array([[c, s], [-s, c]]) + np.asarray(box.center[:2], np.float64)


def footprints(boxes) -> np.ndarray:
    """(n, 4, 2) corners of the footprints of ``boxes``."""
    return np.stack([footprint(b) for b in boxes]) if len(boxes) else np.zeros((0, 4, 2))


def _axes(q: np.ndarray) -> np.ndarray:
    """(k, 4, 2) unit normals of the four edges of the (k, 4, 2) quads ``q`` (0 for a zero-length edge)."""
    e = np.roll(q, -1, axis=1) - q
    n = np.stack([-e[..., 1], e[..., 0]], -1)
    norm = np.linalg.norm(n, axis=-1, keepdims=True)
    return np.divide(n, norm, out=np.zeros_like(n), where=norm > 0)


def quads_touch(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(k,) bool: does convex quad ``a[i]`` touch or overlap ``b[i]`` ((k, 4, 2) each)?

    Separating axes: the edge normals of both quads; the pair is apart only when on one of them
    the projections are more than :data:`SLACK_M` apart.
    """
    axes = np.concatenate([_axes(a), _axes(b)], 1)                     # (k, 8, 2)
    pa = np.einsum("kad,kpd->kap", axes, a)                            # (k, 8, 4)
    pb = np.einsum("kad,kpd->kap", axes, b)
    apart = (pa.max(2) < pb.min(2) - SLACK_M) | (pb.max(2) < pa.min(2) - SLACK_M)
    return ~apart.any(1)


def touching(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(n, m) bool: which of the (n, 4, 2) footprints ``a`` touch or overlap which of ``b`` (m, 4, 2)."""
    a, b = np.asarray(a, np.float64).reshape(-1, 4, 2), np.asarray(b, np.float64).reshape(-1, 4, 2)
    out = np.zeros((len(a), len(b)), bool)
    if not (len(a) and len(b)):
        return out
    ca, cb = a.mean(1), b.mean(1)                                      # broad phase: bounding circles
    ra = np.linalg.norm(a - ca[:, None], axis=-1).max(1)
    rb = np.linalg.norm(b - cb[:, None], axis=-1).max(1)
    d = np.linalg.norm(ca[:, None] - cb[None], axis=-1)
    i, j = np.nonzero(d <= ra[:, None] + rb[None] + 1e-6)
    if len(i):
        out[i, j] = quads_touch(a[i], b[j])
    return out


class _Tracks:
    """The tracks of ``actors`` packed for footprints of all of them at once: each interpolated as
    :class:`generator.world.actors.Track` does (linear in time between samples, clamped to its span),
    each box placed as :meth:`generator.world.actors.Actor.box` places it (its centre turned by the
    heading, then moved to the position)."""

    CHECK_EVERY = 20     #: every this many calls, the footprints are checked against the actors' own boxes

    def __init__(self, actors):
        self.actors = list(actors)
        n = np.array([len(a.track.yaw) for a in self.actors], np.int64)
        width = int(n.max(initial=1)) + 1                 # one spare sample: index i + 1 always exists
        self.t0 = np.array([a.track.t0 for a in self.actors], np.float64)
        self.dt = np.array([a.track.dt for a in self.actors], np.float64)
        self.n = n
        self.xyz = np.zeros((len(n), width, 3))
        self.yaw = np.zeros((len(n), width))
        for k, a in enumerate(self.actors):              # pad with the last sample (a held pose)
            self.xyz[k, :n[k]], self.xyz[k, n[k]:] = a.track.xyz, a.track.xyz[-1]
            self.yaw[k, :n[k]], self.yaw[k, n[k]:] = a.track.yaw, a.track.yaw[-1]
        self.centre = np.array([a.box_center for a in self.actors], np.float64).reshape(-1, 3)
        self.half = np.array([a.size[:2] for a in self.actors], np.float64).reshape(-1, 2) / 2.0
        #: walkers: their box is the extent of the gait-phase mesh they show (phase by walked distance)
        self.walkers = [k for k, a in enumerate(self.actors) if getattr(a, "gait", None) is not None]
        self.calls = 0

    def _phase_boxes(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """((n, 3) local box centres, (n, 2) half sizes) at ``t``: a walker's those of its phase mesh then."""
        centre, half = self.centre.copy(), self.half.copy()
        for k in self.walkers:
            g = self.actors[k].gait
            j = int(g.index(self.actors[k].track, t)[0])
            centre[k] = (g.lo[j] + g.hi[j]) / 2
            half[k] = (g.hi[j, :2] - g.lo[j, :2]) / 2
        return centre, half

    def poses(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """((n, 2) box centres, (n,) yaws) of the actors at time ``t`` (s)."""
        return self._poses(t)[:2]

    def _poses(self, t: float):
        """:meth:`poses`, and the actors' own boxes when this call checked against them (else None)."""
        rows = np.arange(len(self.n))
        x = np.clip((float(t) - self.t0) / self.dt, 0.0, self.n - 1.0)
        i = np.where(self.n > 1, np.minimum(np.floor(x).astype(np.int64), self.n - 2), 0)
        f = x - i
        p = self.xyz[rows, i] * (1 - f[:, None]) + self.xyz[rows, i + 1] * f[:, None]
        h = self.yaw[rows, i] * (1 - f) + self.yaw[rows, i + 1] * f
        c, s = np.cos(h), np.sin(h)
        centre, self._half_t = self._phase_boxes(t) if self.walkers else (self.centre, self.half)
        cx = c * centre[:, 0] - s * centre[:, 1] + p[:, 0]
        cy = s * centre[:, 0] + c * centre[:, 1] + p[:, 1]
        xy, boxes = np.stack([cx, cy], -1), None
        if self.calls % self.CHECK_EVERY == 0:            # the actors' own boxes say the same
            boxes = [a.box(t) for a in self.actors]
            own = np.array([b.center[:2] for b in boxes], np.float64).reshape(-1, 2)
            assert np.abs(own - xy).max(initial=0.0) < 1e-9, f"the kit's box centres are not the actors' at t={t}"
            assert all(abs(b.yaw - y) < 1e-12 for b, y in zip(boxes, h, strict=True)), t
        self.calls += 1
        return xy, h, boxes

    def quads(self, t: float) -> np.ndarray:
        """(n, 4, 2) footprints of the actors at time ``t`` (s)."""
        xy, h, boxes = self._poses(t)
        c, s = np.cos(h)[:, None], np.sin(h)[:, None]
        sx, sy = np.array([-1.0, 1.0, 1.0, -1.0]), np.array([-1.0, -1.0, 1.0, 1.0])
        lx, ly = sx * self._half_t[:, :1], sy * self._half_t[:, 1:]               # (n, 4) box-frame corners
        q = np.stack([xy[:, :1] + lx * c - ly * s, xy[:, 1:] + lx * s + ly * c], -1)
        if boxes is not None:                            # checked against the actors' own boxes
            err = np.abs(footprints(boxes) - q).max(initial=0.0)
            assert err < 1e-9, f"the kit's footprints are not the actors' boxes at t={t}"
        return q


_PACKED: dict = {"world": None, "packs": {}}    # the packed actor lists of the last world asked about


def _pack(world, actors) -> _Tracks:
    """The packed tracks of ``actors`` (default: every actor of ``world``), kept while ``world`` is the last asked."""
    actors = world.actors if actors is None else actors
    if _PACKED["world"] is not world:
        _PACKED.update(world=world, packs={})
    key = tuple(id(a) for a in actors)              # the actors live as long as the world kept here
    if key not in _PACKED["packs"]:
        _PACKED["packs"][key] = _Tracks(actors)
    return _PACKED["packs"][key]


def actor_quads(world, t: float, actors=None) -> np.ndarray:
    """(n, 4, 2) footprints of ``actors`` (default: every actor of ``world``) at time ``t`` (s): the
    footprints of their boxes (:meth:`generator.world.actors.Actor.box`), all at once."""
    return _pack(world, actors).quads(t)


def actor_poses(world, t: float, actors=None) -> tuple[np.ndarray, np.ndarray]:
    """((n, 2) box centres, (n,) yaws) of ``actors`` (default: every actor of ``world``) at time ``t``
    (s): the centres and yaws of their boxes (:meth:`generator.world.actors.Actor.box`), all at once."""
    return _pack(world, actors).poses(t)


def ego_box(world, t: float) -> Box:
    """The ego vehicle's box at time ``t`` (s)."""
    E = world.ego.T_world_ego(t)[0]
    return Box((E[0, 3], E[1, 3], 0.7), EGO_SIZE_M, float(np.arctan2(E[1, 0], E[0, 0])))


def static_quads(scene) -> np.ndarray:
    """(n, 4, 2) footprints of the placed things (instance id > 0) of ``scene``."""
    return footprints([o.box for o in scene.objects if o.instance_id > 0])


def assert_no_contact(world, t: float, parked: np.ndarray | None = None, ego: bool = True) -> np.ndarray:
    """No two actors overlap at ``t``, none touches the ego (unless ``ego`` is False), and none a
    ``parked`` footprint. Returns the (n, 4, 2) actor footprints at ``t``."""
    q = actor_quads(world, t)
    ov = touching(q, q)
    np.fill_diagonal(ov, False)
    assert not ov.any(), f"actors {np.argwhere(ov)[0]} overlap at t={t:.1f}"
    if ego:
        assert not touching(footprint(ego_box(world, t))[None], q).any(), f"an actor touches the ego at t={t:.1f}"
    if parked is not None:
        assert not touching(q, parked).any(), f"an actor touches a static object at t={t:.1f}"
    return q


def assert_vehicles_miss_people(world, t: float, vehicles: list, people: list) -> None:
    """No vehicle (nor the ego) touches a person at ``t``."""
    p = actor_quads(world, t, people)
    hit = touching(np.concatenate([actor_quads(world, t, vehicles), footprint(ego_box(world, t))[None]]), p)
    assert not hit.any(), (t, np.argwhere(hit)[:3])
