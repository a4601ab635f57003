"""Optical flow between two images of one camera stream, from depth, instances and poses.

For every pixel of image A (exposed at ``t_a``) with a surface (finite depth), the point the
pixel centre sees, ``X = depth * ray`` (camera A frame), is carried to time ``t_b`` by its
object's rigid motion (the static town does not move; an actor moves with its track,
:mod:`generator.world.kinematics`; a walker's limbs also with their gait,
:mod:`generator.motion.articulation`) and projected with camera B's pose and intrinsics. The flow
is the projection minus the pixel centre, in pixels (``u`` right, ``v`` down), as KITTI and
Middlebury define it: pixel ``(row, col)`` of A moves to ``(col + 0.5 + u, row + 0.5 + v)`` in
B's pixel coordinates (origin at the top-left corner).

Flags per pixel (:data:`KNOWN`, :data:`VISIBLE`, :data:`ACTOR`, bits of a uint8):

* ``KNOWN`` -- the pixel sees a surface and that point is in front of camera B at ``t_b``
  (farther than :data:`NEAR_M` along its axis): its flow is defined, even if the point leaves the
  image or is hidden in B (KITTI's ``flow_occ``);
* ``VISIBLE`` -- also inside image B and not occluded there: its distance from camera B agrees
  with B's depth pass at the landing position, with the occlusion test fusion uses
  (:func:`generator.fusion.projection.visible`: tolerance ``max(0.1 m, 1 %)``, sub-pixel
  prediction on slanted surfaces) -- KITTI's ``flow_noc``;
* ``ACTOR`` -- the point belongs to an actor (:func:`generator.motion.owners.pixel_owners`), so its
  flow is the ego's and the actor's motion together; elsewhere it is the ego's alone.

No render and no ray cast: the depth and instance passes of A and B and the poses suffice.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from generator.fusion.projection import Projection, visible
from generator.geometry.transforms import invert
from generator.motion.articulation import carry
from generator.motion.owners import pixel_owners
from generator.world.rig import pixel_rays

KNOWN, VISIBLE, ACTOR = np.uint8(1), np.uint8(2), np.uint8(4)
#: A point must be this far in front of camera B (along its optical axis) to have a flow, metres.
NEAR_M = 0.1


@dataclass
class View:
    """One image as the flow sees it.

    Attributes
    ----------
    depth : (H, W) float32
        Distance along each pixel-centre ray to the real geometry, metres; inf = sky.
    instance : (H, W) integer
        Instance pass.
    K : (3, 3) float64
        Intrinsics.
    T_world_camera : (4, 4) float64
        Optical camera frame -> world at the exposure.
    t : float
        Exposure time on the world's timeline, seconds.
    """

    depth: np.ndarray
    instance: np.ndarray
    K: np.ndarray
    T_world_camera: np.ndarray
    t: float

    @property
    def shape(self) -> tuple[int, int]:
        return self.depth.shape

    def points(self) -> tuple[np.ndarray, np.ndarray]:
        """((H, W, 3) float64 surface points in the camera frame (0 for sky), (H, W) bool known)."""
        h, w = self.shape
        known = np.isfinite(self.depth) & (self.depth > 0)
        d = np.where(known, self.depth, 0.0).astype(np.float64)
        return _rays(self.K.tobytes(), w, h) * d[..., None], known


@functools.lru_cache(maxsize=8)
def _rays(k_bytes: bytes, w: int, h: int) -> np.ndarray:
    return pixel_rays(np.frombuffer(k_bytes, np.float64).reshape(3, 3), w, h)


@dataclass
class Flow:
    """Flow of every pixel of image A to image B.

    Attributes
    ----------
    uv : (H, W, 2) float32
        Displacement in pixels (u right, v down); 0 where not ``KNOWN``.
    flags : (H, W) uint8
        :data:`KNOWN` | :data:`VISIBLE` | :data:`ACTOR` bits.
    """

    uv: np.ndarray
    flags: np.ndarray

    @property
    def known(self) -> np.ndarray:
        return (self.flags & KNOWN) > 0

    @property
    def visible(self) -> np.ndarray:
        return (self.flags & VISIBLE) > 0


def optical_flow(a: View, b: View, movers_ab: list) -> Flow:
    """Flow of every pixel of ``a`` to image ``b``.

    Parameters
    ----------
    a, b : View
        Two images of one camera stream (any order in time: ``b`` earlier gives the backward flow).
    movers_ab : list of generator.world.kinematics.Mover
        The actors between ``a.t`` (``T0``) and ``b.t`` (``T1``).

    Returns
    -------
    Flow
    """
    h, w = a.shape
    X, known = a.points()
    Xw = X @ a.T_world_camera[:3, :3].T + a.T_world_camera[:3, 3]
    owner = pixel_owners(Xw, known, a.instance, movers_ab)
    T_b_w = invert(b.T_world_camera)
    Y = np.empty_like(X)
    rel = T_b_w @ a.T_world_camera  # static town: camera A -> camera B
    Y[...] = X @ rel[:3, :3].T + rel[:3, 3]
    for i in np.unique(owner[owner >= 0]):
        sel = owner == i
        if movers_ab[i].meshes is not None:  # a walker whose limbs moved: each point with its limb
            Y[sel] = carry(movers_ab[i], Xw[sel]) @ T_b_w[:3, :3].T + T_b_w[:3, 3]
            continue
        T = T_b_w @ movers_ab[i].M @ a.T_world_camera
        Y[sel] = X[sel] @ T[:3, :3].T + T[:3, 3]
    z = Y[..., 2]
    front = known & (z > NEAR_M)
    zs = np.where(front, z, 1.0)
    K = b.K
    u = K[0, 0] * Y[..., 0] / zs + K[0, 1] * Y[..., 1] / zs + K[0, 2]
    v = K[1, 1] * Y[..., 1] / zs + K[1, 2]
    uc, vc = np.meshgrid(np.arange(w) + 0.5, np.arange(h) + 0.5)
    uv = np.stack([np.where(front, u - uc, 0.0), np.where(front, v - vc, 0.0)], -1).astype(np.float32)
    flags = np.where(front, KNOWN, np.uint8(0)).astype(np.uint8)
    flags[owner >= 0] |= ACTOR
    hb, wb = b.shape
    inside = front & (u >= 0) & (u < wb) & (v >= 0) & (v < hb)
    idx = np.flatnonzero(inside)
    if len(idx):
        uu, vv, Yi = u.ravel()[idx], v.ravel()[idx], Y.reshape(-1, 3)[idx]
        proj = Projection(idx, uu, vv, np.floor(vv).astype(np.int64), np.floor(uu).astype(np.int64),
                          np.linalg.norm(Yi, axis=1), Yi[:, 2])
        seen = visible(proj, b.depth, b.K)
        flags.reshape(-1)[idx[seen]] |= VISIBLE
    return Flow(uv, flags)
