"""Which beams of a sweep can reach an actor: conservative windows, coarse per sweep, tight per column.

Two stages (:mod:`generator.lidar.actors` uses both; a test checks that neither ever drops a
ray that an actor would stop):

1. :func:`sweep_windows`, once per sweep and actor: the sphere that holds the actor during
   the whole sweep (prototype radius about its origin + the box of the origin's path, whose
   samples are linear in time), seen from the box of the sensor's path, widened by the largest
   emission-point offset and the sensor's rotation during the sweep, gives a window of firing
   columns (encoder azimuth, widened by the spread of the lasers' ``rot_correction``). Actors
   beyond the maximum range get none. Its columns are where the actor's pose is looked up.
2. :func:`column_windows`, per (actor, column) with both poses of that column's instant: the
   actor's box (the prototype's bounding box under the actor's pose) seen from the sensor in its
   frame at that instant bounds the beam azimuth (the box's half-width across the line of sight
   over its nearest depth) and elevation (its height range over its horizontal distance range),
   widened only by the emission-point offsets (across the beam only the 2.6 cm horizontal one). No motion
   margin is needed: both poses are exact there. For a car 10 m ahead the beams kept are about a quarter
   of the sphere's.

Frames: ``poses`` are ``T_world_sensor``; beam azimuths are CCW from the sensor's +x, elevations
from its xy-plane; ring ``r`` is the ``r``-th highest beam.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

EPS = 1e-3  #: metres / radians of slack on every bound (float32 rays vs float64 poses)


@dataclass(frozen=True)
class BeamTable:
    """A sensor's beams as the windows need them.

    Attributes
    ----------
    neg_elevation : (L,) float64
        Minus each ring's elevation (ascending: ring 0 is the highest beam), radians.
    rot : (L,) float64
        Each ring's ``rot_correction`` (beam azimuth = encoder azimuth + rot), radians.
    psi : (steps,) float64
        Encoder azimuth of each column, radians.
    offset : float
        Largest distance of an emission point from the sensor origin, metres.
    lateral, radial : float
        Largest horizontal offset of an emission point across / along its own beam's azimuth,
        metres (the driver's ``horiz_offset``, and ``vert_offset`` times the sine of the elevation).
    sensor : generator.lidar.sensors.Sensor
    spread : float
        Largest angle of a sub-ray from its beam (beam divergence, :mod:`generator.lidar.returns`),
        radians; every angular bound is widened by it (0: the beams themselves).
    """

    neg_elevation: np.ndarray
    rot: np.ndarray
    psi: np.ndarray
    offset: float
    lateral: float
    radial: float
    sensor: object
    spread: float = 0.0

    @classmethod
    def of(cls, sensor, spread: float = 0.0) -> BeamTable:
        order = sensor.by_ring
        o, _, _ = sensor.local_rays()
        return cls(-sensor.elevation[order], sensor.rot_correction[order], sensor.column_azimuth(),
                   float(np.linalg.norm(o, axis=-1).max()), float(np.abs(sensor.horiz_offset).max()),
                   float(np.abs(sensor.vert_offset * np.sin(sensor.elevation)).max()), sensor, float(spread))


def sweep_windows(beams: BeamTable, radius: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                  poses: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Column windows of every actor that may be hit during a sweep (stage 1).

    Parameters
    ----------
    radius : (n,) float64
        Largest distance of a prototype vertex from the actor's origin, metres.
    lo, hi : (n, 3) float64
        Box of each actor origin's path during the sweep, world frame, metres.
    poses : (steps, 4, 4) or (1, 4, 4) float64
        ``T_world_sensor`` of every firing column (or of the whole sweep).

    Returns
    -------
    actor, c0, c1 : (K,) int64
        Candidate actor and its columns ``[c0, c1)``; a window that wraps past column 0 is two.
    """
    s = beams.sensor
    S = np.ascontiguousarray(poses[:, :3, 3])
    s_mid, s_rad = (S.min(0) + S.max(0)) / 2, np.linalg.norm(S.max(0) - S.min(0)) / 2
    R0 = poses[0, :3, :3]
    turn = float(np.arccos(np.clip((np.einsum("ij,kij->k", R0, poses[:, :3, :3]).min() - 1) / 2, -1, 1)))
    r_tot = radius + np.linalg.norm(hi - lo, axis=1) / 2 + s_rad + beams.offset + EPS
    v = ((lo + hi) / 2 - s_mid) @ R0  # sensor axes at the sweep start
    d_xy, d = np.hypot(v[:, 0], v[:, 1]), np.linalg.norm(v, axis=1)
    # a beam's direction in the start frame is within `turn` of its own; its azimuth within turn / cos(elevation)
    tilt = min(float(np.abs(beams.neg_elevation).max()) + turn, 1.5)
    half = np.arcsin(np.minimum(1.0, r_tot / np.maximum(d_xy, 1e-9))) + turn / np.cos(tilt) + EPS
    if beams.spread:
        half = half + beams.spread / np.cos(tilt)
    az = np.arctan2(v[:, 1], v[:, 0])
    lo_psi, hi_psi = az - half - beams.rot.max(), az + half - beams.rot.min()
    k, start = s.azimuth_steps / (2 * np.pi), s.start_azimuth_rad
    lo_c, hi_c = (
        ((start - hi_psi) * k, (start - lo_psi) * k) if s.clockwise else ((lo_psi - start) * k, (hi_psi - start) * k)
    )
    ca = np.floor(lo_c).astype(np.int64) - 1
    width = np.floor(hi_c).astype(np.int64) + 2 - ca
    every = (d_xy <= r_tot) | (half >= np.pi) | (width >= s.azimuth_steps)
    ca = np.where(every, 0, np.mod(ca, s.azimuth_steps))
    width = np.where(every, s.azimuth_steps, width)
    # the sphere must also cross some beam's elevation (the per-column stage does the real work)
    el, beta = np.arctan2(v[:, 2], d_xy), np.arcsin(np.minimum(1.0, r_tot / np.maximum(d, 1e-9))) + turn + EPS
    if beams.spread:
        beta = beta + beams.spread
    crosses = (el - beta <= -beams.neg_elevation[0]) & (el + beta >= -beams.neg_elevation[-1])
    alive = np.flatnonzero((d - r_tot < s.max_range_m) & crosses)
    first = np.minimum(ca[alive] + width[alive], s.azimuth_steps)
    wrap = ca[alive] + width[alive] - s.azimuth_steps
    two = wrap > 0
    return (np.concatenate([alive, alive[two]]), np.concatenate([ca[alive], np.zeros(int(two.sum()), np.int64)]),
            np.concatenate([first, wrap[two]]))


def column_windows(beams: BeamTable, position: np.ndarray, yaw: np.ndarray, box_center: np.ndarray,
                   box_half: np.ndarray, poses: np.ndarray) -> dict[str, np.ndarray]:
    """Tight windows of ``m`` (actor, column) pairs (stage 2).

    Parameters
    ----------
    position, yaw : (m, 3), (m,) float64
        Actor origin (world frame, metres) and heading (radians) at the column's firing time.
    box_center, box_half : (m, 3) float64
        Centre and half extents of the prototype's bounding box, actor frame, metres.
    poses : (m, 4, 4) float64
        ``T_world_sensor`` at the column's firing time.

    Returns
    -------
    dict of (m,) arrays
        ``azimuth``, ``half``: beams farther than ``half`` from ``azimuth`` miss (radians, sensor
        frame); ``ring0``, ``ring1``: only rings ``[ring0, ring1)`` can hit; ``near`` (float32):
        no hit nearer than this, metres.
    """
    m = len(yaw)
    out = {"azimuth": np.empty(m), "half": np.empty(m), "ring0": np.empty(m, np.int64), "ring1": np.empty(m, np.int64),
           "near": np.empty(m, np.float32)}
    # a sub-ray leaves its beam by up to `spread`, in azimuth by up to spread / cos(elevation)
    widen = (beams.spread / np.cos(min(float(np.abs(beams.neg_elevation).max()) + beams.spread, 1.5))
             if beams.spread else 0.0)
    _column_windows(np.ascontiguousarray(position, np.float64), np.ascontiguousarray(yaw, np.float64),
                    np.ascontiguousarray(box_center, np.float64), np.ascontiguousarray(box_half, np.float64),
                    np.ascontiguousarray(poses, np.float64), np.ascontiguousarray(beams.neg_elevation, np.float64),
                    float(beams.lateral), float(beams.radial), float(beams.offset), float(beams.spread), widen,
                    out["azimuth"], out["half"], out["ring0"], out["ring1"], out["near"])
    return out


@njit(nogil=True, cache=True)
def _column_windows(position, yaw, box_center, box_half, poses, neg_el, lateral, radial, offset, spread, widen,
                    azimuth, half, ring0, ring1, near):  # pragma: no cover - compiled
    """:func:`column_windows`, one (actor, column) pair at a time (written into the last five arrays)."""
    off = offset + EPS
    a, v = np.empty((3, 3)), np.empty(3)
    for k in range(yaw.shape[0]):
        c, s = np.cos(yaw[k]), np.sin(yaw[k])
        bx, by, bz = box_center[k, 0], box_center[k, 1], box_center[k, 2]
        d0 = position[k, 0] + (c * bx - s * by) - poses[k, 0, 3]
        d1 = position[k, 1] + (s * bx + c * by) - poses[k, 1, 3]
        d2 = position[k, 2] + bz - poses[k, 2, 3]
        for i in range(3):  # box centre, sensor frame
            v[i] = poses[k, 0, i] * d0 + poses[k, 1, i] * d1 + poses[k, 2, i] * d2
        for j in range(3):  # the actor's axes, sensor frame
            a[0, j] = c * poses[k, 0, j] + s * poses[k, 1, j]
            a[1, j] = c * poses[k, 1, j] - s * poses[k, 0, j]
            a[2, j] = poses[k, 2, j]
        rho = max(np.hypot(v[0], v[1]), 1e-9)
        ux, uy = v[0] / rho, v[1] / rho
        # support of the box along the horizontal line of sight, across it and along the sensor's z
        along, across, up, q2 = 0.0, 0.0, 0.0, 0.0
        for i in range(3):
            h = box_half[k, i]
            along += h * abs(a[i, 0] * ux + a[i, 1] * uy)
            across += h * abs(a[i, 1] * ux - a[i, 0] * uy)
            up += h * abs(a[i, 2])
            # distance from the sensor origin to the box, in the box's axes
            g = max(abs(a[i, 0] * v[0] + a[i, 1] * v[1] + a[i, 2] * v[2]) - h, 0.0)
            q2 += g * g
        # a beam's horizontal trace is the line at its azimuth shifted across by the horizontal offset;
        # its start moves along it by the vertical offset's horizontal part
        depth = rho - along - radial - EPS
        half[k] = (np.arctan2(across + lateral + EPS, max(depth, 1e-9)) if depth > 0 else 4.0) + EPS + widen
        # horizontal distance of box points: at least the depth of the box's near face, at most its far corner's
        r_lo, r_hi = rho - along - off, np.hypot(rho + along, across) + off
        z_lo, z_hi = v[2] - up - off, v[2] + up + off
        inside = r_lo <= 0
        r_lo = max(r_lo, 1e-9)
        el_hi = (np.pi / 2 if inside else np.arctan2(z_hi, r_lo if z_hi >= 0 else r_hi)) + EPS + spread
        el_lo = (-np.pi / 2 if inside else np.arctan2(z_lo, r_lo if z_lo <= 0 else r_hi)) - EPS - spread
        ring0[k] = np.searchsorted(neg_el, -el_hi, side="left")
        ring1[k] = np.searchsorted(neg_el, -el_lo, side="right")
        near[k] = np.float32(np.sqrt(q2) - off)
        azimuth[k] = np.arctan2(v[1], v[0])
