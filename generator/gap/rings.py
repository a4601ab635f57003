"""Which laser and firing column a point came from, derived from its position alone.

A KITTI ``.bin`` keeps x, y, z and remission: no ring, no column. Counting the rays a sensor lost needs
them, so they are recovered from the geometry with the sensor's calibration (the HDL-64E S3 table of
``../shared/reference/velodyne_hdl64e_s3_calibration.yaml``, urbangen's ``hdl64e`` preset,
:mod:`generator.lidar.sensors`), whose point equations are the Velodyne driver's::

    x = A cos(phi) - h sin(phi),   y = A sin(phi) + h cos(phi),   z = d sin(v) + vo cos(v)
    A = d cos(v) - vo sin(v),      phi = psi + rot_correction

for laser elevation ``v``, vertical and horizontal emission offsets ``vo`` and ``h``, range ``d`` and
encoder azimuth ``psi``.

Ring
----
Eliminating ``d``: a point lies on laser ``i``'s cone exactly when ``z cos(v_i) - A_i sin(v_i) = vo_i``,
with ``A_i = sqrt(x^2 + y^2 - h_i^2)``. The signed left-hand side minus ``vo_i`` is the point's vertical
distance from that cone in the beam's vertical plane (metres). Each point takes the laser with the
smallest such distance, searched among the lasers next to the point's elevation as seen from each group
of lasers' emission height (the HDL-64E's upper and lower blocks sit 6 cm apart, which at the 0.9 m
minimum range is worth several lasers; within a block the offset changes by under a millimetre from
one laser to the next, so the neighbours of the refined elevation hold the right cone). The miss is
kept (``vertical_m``): on a simulated sensor it is zero to float precision; jitter, range noise of a real
unit, a calibration that is not the unit's own, and vibration make it spread -- seed 002's "rings are not
perfect circles", measured.

Column
------
With the laser known, ``phi = atan2(y, x) - atan2(h, A)`` and ``psi = phi - rot_correction``; the column is
``psi`` rounded to the sensor's azimuth grid (``start_azimuth``, spin direction, ``azimuth_steps``). For
urbangen's own scans this is exact. A real unit's firing count per turn drifts with its motor speed
(KITTI's HDL-64E gives about 2000-2100 columns per 10 Hz turn) and its azimuth offsets are its own, so
on real data a column is an azimuth bin of the calibration's grid: two points can share a cell
(``collisions`` counts them) and a lost ray is counted as a cell no point fell into.

When it fails
-------------
Adjacent HDL-64E lasers are 0.33-0.5 degrees apart. A point is put on the wrong ring when its elevation
error exceeds half that: on a real unit whose elevations differ from the table by more (use its own
calibration then, ``--sensor FILE.yaml``), or on scans jittered by more than about ``range x 0.003`` m
vertically (seed 002's +-5 cm jitter within ~15 m). The spread of ``vertical_m`` says how close the fit is.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Lasers tried per point and laser group: the one below the estimated elevation and the next above.
CANDIDATES = 3
#: A jump in emission height (vert_offset) larger than this starts a new laser group, metres.
GROUP_GAP_M = 0.02


@dataclass
class RingFit:
    """The derived beam of each point.

    Attributes
    ----------
    ring : (n,) int16
        Elevation rank of the laser, 0 = highest.
    column : (n,) int32
        Firing column (azimuth bin of the sensor's grid), ``0 .. azimuth_steps - 1``.
    vertical_m : (n,) float32
        Signed vertical distance from the assigned laser's cone, metres.
    range_m : (n,) float32
        Distance from the sensor origin, metres.
    """

    ring: np.ndarray
    column: np.ndarray
    vertical_m: np.ndarray
    range_m: np.ndarray


class RingModel:
    """Ring and column assignment for one sensor (a :class:`generator.lidar.sensors.Sensor`)."""

    def __init__(self, sensor):
        order = np.argsort(sensor.elevation, kind="stable")  # ascending elevation
        self.sensor = sensor
        self.elev = sensor.elevation[order].astype(np.float64)
        self.vo = sensor.vert_offset[order].astype(np.float64)
        self.h = sensor.horiz_offset[order].astype(np.float64)
        self.rot = sensor.rot_correction[order].astype(np.float64)
        self.ring_of = sensor.ring[order].astype(np.int16)
        self.steps = int(sensor.azimuth_steps)
        self.cos, self.sin = np.cos(self.elev).astype(np.float32), np.sin(self.elev).astype(np.float32)
        self.h2, self.vo32 = (self.h ** 2).astype(np.float32), self.vo.astype(np.float32)
        # lasers grouped by emission height (the HDL-64E's two blocks sit ~6 cm apart): within a group the
        # offset changes slowly with elevation, so the elevation seen from the group's own offset finds the
        # laser's neighbours even at the minimum range
        by_vo = np.argsort(self.vo, kind="stable")
        cuts = np.flatnonzero(np.diff(self.vo[by_vo]) > GROUP_GAP_M) + 1
        self.groups = [np.sort(g) for g in np.split(by_vo, cuts)]

    def _candidates(self, rho: np.ndarray, z: np.ndarray) -> list[np.ndarray]:
        """Laser indices (into the elevation-sorted table) to try for each point: per group, the lasers
        around the point's elevation seen from the group's emission point (for the true laser,
        ``atan2(z - vo cos v, rho + vo sin v) = v`` exactly; two refinements get there)."""
        out = []
        for g in self.groups:
            elev, vo = self.elev[g], self.vo[g]
            guess = np.arctan2(z - vo.mean(), rho)
            for _ in range(2):  # the elevation seen from the emission point, which sits at vo (-sin v, cos v)
                off = np.interp(guess, elev, vo)
                guess = np.arctan2(z - off * np.cos(guess), rho + off * np.sin(guess))
            k = np.searchsorted(elev, guess)
            for j in range(-1, CANDIDATES - 1):
                out.append(g[np.clip(k + j, 0, len(g) - 1)])
        return out

    def fit(self, xyz: np.ndarray) -> RingFit:
        """The beam of every point of ``xyz`` (n, 3) (sensor frame, metres)."""
        p = np.asarray(xyz, np.float32)  # float32 holds 120 m to 10 um: far below a laser's 0.3-deg spacing
        x, y, z = p[:, 0], p[:, 1], p[:, 2]
        rho2 = x * x + y * y
        best_miss = np.full(len(p), np.inf, np.float32)
        laser = np.zeros(len(p), np.int64)
        a_best = np.zeros(len(p), np.float32)
        for c in self._candidates(np.sqrt(rho2), z):  # one candidate at a time: (n,) arrays, no (n, C)
            a = np.sqrt(np.maximum(rho2 - self.h2[c], 0.0))
            miss = z * self.cos[c] - a * self.sin[c] - self.vo32[c]
            better = np.abs(miss) < np.abs(best_miss)
            best_miss = np.where(better, miss, best_miss)
            laser = np.where(better, c, laser)
            a_best = np.where(better, a, a_best)
        psi = (np.arctan2(y, x).astype(np.float64) - np.arctan2(self.h[laser], a_best) - self.rot[laser])
        s = self.sensor
        sign = -1.0 if s.clockwise else 1.0
        col = np.rint(sign * (psi - s.start_azimuth_rad) * (self.steps / (2.0 * np.pi))).astype(np.int64) % self.steps
        return RingFit(self.ring_of[laser], col.astype(np.int32), best_miss.astype(np.float32),
                       np.sqrt(rho2 + z * z).astype(np.float32))
