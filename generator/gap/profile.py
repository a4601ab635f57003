"""One dataset measured: the histograms every ``gap`` curve and distance is computed from.

Per scan (:meth:`Profile.add`), with the beams derived from the geometry (:mod:`generator.gap.rings`):

* **rays**: points per ring; the range image (ring x column, the nearest point of a cell; ``collisions``
  counts points sharing a cell). A cell without a point is a lost ray. Its range is estimated from the
  nearest returned cell of the same ring within :data:`GAP_COLUMNS` columns (the nearer one; on a tie
  the nearer range): a ray lost amid returns had a surface to hit at about that distance. A cell with no
  return that near (sky, beyond the range) has no estimate and counts only per ring. Per range bin,
  every point is a returned ray and each point that shares its cell cancels one empty cell of its bin
  (it was fired into one of the empty cells near it: jittered points, or a real unit's own azimuths);
  the lost share of a bin is lost / (lost + returned).
* **range**: points per range bin.
* **ring regularity**: along each ring (points in column order), the distance of each point's range
  from the median of the 5 consecutive points centred on it, where those 5 lie within 8 columns: on any
  smooth surface that median is the point itself (a monotonic run), so a perfect simulated ring scores 0
  except at edges, and noise or jitter shows at once. Also the vertical distance from the laser's cone
  (``vertical_m`` of the ring fit).
* **intensity**: remission histogram, overall and per SemanticKITTI learning class.
* **class mix**: points per learning class.
* **objects**: per object (box or thing instance, :mod:`generator.gap.objects`), its distance and points.
"""

from __future__ import annotations

import numpy as np

from generator.gap.objects import ObjectCounts
from generator.gap.rings import RingFit, RingModel
from generator.gap.window import Window

N_LEARNING = 20
RANGE_EDGES = np.arange(0.0, 122.0, 2.0)           # points per range bin, metres
LOST_RANGE_EDGES = np.arange(0.0, 125.0, 5.0)      # rays lost per range bin, metres
#: ring regularity, metres: 0, then log-spaced 0.1 mm .. 1 m (the last bin holds the rest)
RESIDUAL_EDGES = np.concatenate([[0.0], np.geomspace(1e-4, 1.0, 161)])
VERTICAL_EDGES = np.linspace(-0.25, 0.25, 501)    # distance from the cone, metres
INTENSITY_EDGES = np.linspace(0.0, 1.0, 101)
OBJECT_DISTANCE_EDGES = np.array([0.0, 10.0, 20.0, 30.0, 40.0, 60.0, 80.0, 120.0])
LOG_POINTS_EDGES = np.linspace(0.0, 5.0, 51)      # log10(points per object)
GAP_COLUMNS = 4
WINDOW_COLUMNS = 8


def _bin(values: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """(n,) int64 bin index of each value, clipped into the first and last bin."""
    n = len(edges) - 1
    width = (edges[-1] - edges[0]) / n
    if np.allclose(np.diff(edges), width):  # even bins: arithmetic, not a search
        idx = np.floor((np.asarray(values, np.float64) - edges[0]) * (1.0 / width))
        return np.clip(idx, 0, n - 1).astype(np.int64)
    return np.clip(np.searchsorted(edges, values, side="right") - 1, 0, n - 1)


class Profile:
    """Histograms of one dataset (see the module docstring).

    Parameters
    ----------
    name : str
    model : RingModel
    window : Window, optional
        Only the rays and points inside it are measured (:mod:`generator.gap.window`); None: all.
    """

    def __init__(self, name: str, model: RingModel, window: Window | None = None):
        self.name, self.model = name, model
        rings, nb = len(model.elev), len(RESIDUAL_EDGES) - 1
        self.rings, self.steps = rings, model.steps
        #: (rings, steps) bool rays inside the window, or None (every ray)
        self.cells = None if window is None or window.whole else window.cells(model)
        #: (rings,) int64 rays per scan of each ring inside the window
        self.rays_per_ring = (np.full(rings, model.steps, np.int64) if self.cells is None
                              else self.cells.sum(1).astype(np.int64))
        self.scans = 0
        self.points = 0
        self.collisions = 0
        self.ring_points = np.zeros(rings, np.int64)
        self.returned_range = np.zeros(len(LOST_RANGE_EDGES) - 1, np.int64)
        self.lost_range = np.zeros(len(LOST_RANGE_EDGES) - 1, np.int64)
        self.range_hist = np.zeros(len(RANGE_EDGES) - 1, np.int64)
        self.residual = np.zeros((rings, nb), np.int64)
        self.vertical = np.zeros(len(VERTICAL_EDGES) - 1, np.int64)
        self.intensity = np.zeros((N_LEARNING, len(INTENSITY_EDGES) - 1), np.int64)
        self.labelled = False
        self.objects = np.zeros((len(OBJECT_DISTANCE_EDGES) - 1, len(LOG_POINTS_EDGES) - 1), np.int64)
        self.object_classes: dict[str, np.ndarray] = {}

    def crop(self, xyz: np.ndarray, ring: np.ndarray | None = None) -> tuple[np.ndarray | None, RingFit | None]:
        """(keep, fit): which points of ``xyz`` (n, 3) lie in a ray of the window, and the ring fit of those.

        Both None without a window (every point is measured; :meth:`measure` fits them itself). ``ring``
        (n,) replaces the fitted ring when the format records it.
        """
        if self.cells is None:
            return None, None
        fit = self.model.fit(xyz)
        if ring is not None:
            fit.ring = np.asarray(ring, np.int16)
        keep = self.cells[fit.ring, fit.column]
        return keep, RingFit(fit.ring[keep], fit.column[keep], fit.vertical_m[keep], fit.range_m[keep])

    def measure(self, xyz: np.ndarray, remission: np.ndarray, learning: np.ndarray | None,
                objects: ObjectCounts | None = None, ring: np.ndarray | None = None,
                fit: RingFit | None = None) -> dict:
        """One scan's counts (pure: safe in a worker thread; :meth:`merge` adds them).

        ``xyz`` (n, 3) sensor frame, metres; ``remission`` (n,) in [0, 1]; ``learning`` (n,) SemanticKITTI
        learning classes or None; ``ring`` (n,) when the format records it; ``fit`` the ring fit of ``xyz``
        when it is known already (:meth:`crop`).
        """
        if fit is None:
            fit = self.model.fit(xyz)
        if ring is not None:
            fit.ring = np.asarray(ring, np.int16)
        cls = np.zeros(len(xyz), np.int64) if learning is None else np.asarray(learning, np.int64)
        nb = len(INTENSITY_EDGES) - 1
        part = {"scans": 1, "points": len(xyz), "labelled": learning is not None,
                "ring_points": np.bincount(fit.ring, minlength=self.rings),
                "range_hist": np.bincount(_bin(fit.range_m, RANGE_EDGES), minlength=len(RANGE_EDGES) - 1),
                "residual": self._regularity(fit),
                "vertical": np.bincount(_bin(fit.vertical_m, VERTICAL_EDGES), minlength=len(VERTICAL_EDGES) - 1),
                "intensity": np.bincount(cls * nb + _bin(remission, INTENSITY_EDGES),
                                         minlength=N_LEARNING * nb).reshape(N_LEARNING, nb),
                "objects": objects}
        part.update(self._rays(fit))
        return part

    def merge(self, part: dict) -> None:
        """Add one scan's counts (:meth:`measure`)."""
        for key in ("scans", "points", "collisions", "ring_points", "range_hist", "residual", "vertical",
                    "intensity", "returned_range", "lost_range"):
            setattr(self, key, getattr(self, key) + part[key])
        self.labelled |= part["labelled"]
        if part["objects"] is not None:
            self._objects(part["objects"])

    def add(self, xyz: np.ndarray, remission: np.ndarray, learning: np.ndarray | None,
            objects: ObjectCounts | None = None, ring: np.ndarray | None = None) -> None:
        """Measure one scan and add it (:meth:`measure`, then :meth:`merge`)."""
        self.merge(self.measure(xyz, remission, learning, objects, ring))

    def _rays(self, fit) -> dict:
        cells_all = fit.ring.astype(np.int64) * self.steps + fit.column
        order = np.lexsort((fit.range_m, cells_all))  # by cell, nearest first
        cells, ranges = cells_all[order], fit.range_m[order]
        kept = np.r_[True, cells[1:] != cells[:-1]]
        grid = np.full((self.rings, self.steps), np.inf, np.float32)
        grid.ravel()[cells[kept]] = ranges[kept]
        occ = np.isfinite(grid)
        w = GAP_COLUMNS
        pad = np.concatenate([grid[:, -w:], grid, grid[:, :w]], axis=1)  # the turn is a circle
        cols = np.arange(pad.shape[1])
        have = np.isfinite(pad)
        left = np.maximum.accumulate(np.where(have, cols, -10 * w), axis=1)
        right = np.minimum.accumulate(np.where(have, cols, 10 * w + pad.shape[1])[:, ::-1], axis=1)[:, ::-1]
        rows = np.arange(self.rings)[:, None]
        dl, dr = cols - left, right - cols
        rl = pad[rows, np.clip(left, 0, pad.shape[1] - 1)]
        rr = pad[rows, np.clip(right, 0, pad.shape[1] - 1)]
        est = np.where(dl < dr, rl, np.where(dr < dl, rr, np.minimum(rl, rr)))
        est = np.where(np.minimum(dl, dr) <= w, est, np.inf)[:, w:-w]
        empty = ~occ & np.isfinite(est)
        if self.cells is not None:
            empty &= self.cells
        n = len(LOST_RANGE_EDGES) - 1
        # every point is a returned ray; one that lost its cell to a nearer point (jitter, a calibration that
        # is not the unit's own, more firings per turn than the grid) came from one of the empty cells near
        # it, so each such point cancels one empty cell of its range bin
        extra = np.bincount(_bin(ranges[~kept], LOST_RANGE_EDGES), minlength=n)
        return {"collisions": int((~kept).sum()),
                "returned_range": np.bincount(_bin(ranges, LOST_RANGE_EDGES), minlength=n),
                "lost_range": np.maximum(np.bincount(_bin(est[empty], LOST_RANGE_EDGES), minlength=n) - extra, 0)}

    def _regularity(self, fit) -> np.ndarray:
        nb = len(RESIDUAL_EDGES) - 1
        order = np.lexsort((fit.column, fit.ring))
        ring, col, r = fit.ring[order], fit.column[order].astype(np.int64), fit.range_m[order]
        n = len(r)
        if n < 5:
            return np.zeros((self.rings, nb), np.int64)
        i = np.arange(2, n - 2)
        ok = (ring[i - 2] == ring[i + 2]) & (col[i + 2] - col[i - 2] <= WINDOW_COLUMNS)
        win = np.stack([r[i + d] for d in (-2, -1, 0, 1, 2)])
        resid = np.abs(r[i] - np.partition(win, 2, axis=0)[2])[ok]
        return np.bincount(ring[i][ok].astype(np.int64) * nb + _bin(resid, RESIDUAL_EDGES),
                           minlength=self.rings * nb).reshape(self.rings, nb)

    def _objects(self, obj: ObjectCounts) -> None:
        keep = obj.points > 0
        d = _bin(obj.distance_m[keep], OBJECT_DISTANCE_EDGES)
        lp = _bin(np.log10(obj.points[keep]), LOG_POINTS_EDGES)
        nb = len(LOG_POINTS_EDGES) - 1
        self.objects += np.bincount(d * nb + lp, minlength=self.objects.size).reshape(self.objects.shape)
        for c, di, li in zip(np.asarray(obj.cls, object)[keep], d, lp, strict=True):
            h = self.object_classes.setdefault(str(c), np.zeros_like(self.objects))
            h[di, li] += 1
