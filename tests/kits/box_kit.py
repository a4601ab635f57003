"""A built scene for the detection tests: a truck hiding half of a car, a car cut by the image border.

Every thing is a box (convex), the camera is level (no pitch, no roll), so the amodal silhouette of a
thing is the convex hull of its projected corners and the truck's near vertical edge projects to a
vertical image line: the expected visibility and truncation are polygon areas, computed here
analytically (no rasteriser involved).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from generator import geometry as M
from generator.world import rig
from kits.scene_kit import make_scene

WIDTH, HEIGHT, HFOV = 320, 240, 60.0
CAM_XYZ = (0.0, 0.0, 1.2)
TRUCK, HIDDEN, CUT = 1, 2, 3


def hull_area(pts: np.ndarray) -> tuple[float, np.ndarray]:
    """Area and counter-clockwise vertices of the convex hull of (n, 2) points."""
    p = sorted(map(tuple, np.asarray(pts, np.float64)))

    def half(points):
        out = []
        for q in points:
            while len(out) >= 2 and np.cross(np.subtract(out[-1], out[-2]), np.subtract(q, out[-2])) <= 0:
                out.pop()
            out.append(q)
        return out

    hull = np.array(half(p)[:-1] + half(p[::-1])[:-1])
    x, y = hull[:, 0], hull[:, 1]
    return 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))), hull


def area_right_of(poly: np.ndarray, u: float) -> float:
    """Area of the part of a convex polygon with x >= u (one Sutherland-Hodgman step)."""
    out = []
    for a, b in zip(poly, np.roll(poly, -1, 0), strict=True):
        ina, inb = a[0] >= u, b[0] >= u
        if ina:
            out.append(a)
        if ina != inb:
            s = (u - a[0]) / (b[0] - a[0])
            out.append(a + s * (b - a))
    if len(out) < 3:
        return 0.0
    q = np.array(out)
    return 0.5 * abs(np.dot(q[:, 0], np.roll(q[:, 1], -1)) - np.dot(q[:, 1], np.roll(q[:, 0], -1)))


@dataclass
class BoxScene:
    scene: object
    T_world_camera: np.ndarray
    K: np.ndarray
    hidden_share: float        # analytic visible share of the car behind the truck
    cut_truncation: float      # analytic share of the border car's silhouette outside the image


def _silhouette(center, size, T_cw, K) -> np.ndarray:
    from generator.detection.frames import corners

    c = T_cw[:3, :3] @ np.asarray(center) + T_cw[:3, 3]
    p = corners(c, size, T_cw[:3, :3])
    return (p @ K.T)[:, :2] / p[:, 2:3]


def box_scene(hfov: float = HFOV, width: int = WIDTH, height: int = HEIGHT) -> BoxScene:
    """The scene, the camera and the analytic answers (see the module docstring)."""
    T_wc = rig.camera_extrinsics(CAM_XYZ, (0.0, 0.0, 0.0))  # optical axis along world +x, level
    T_cw = np.linalg.inv(T_wc)
    K = rig.intrinsics(hfov, width, height)
    car, truck = (4.2, 1.8, 1.5), (2.5, 2.6, 3.2)
    truck_c = np.array([14.0, 0.0, truck[2] / 2])
    hidden_c = np.array([30.0, 0.0, car[2] / 2])
    # slide the car sideways until the truck's right image edge cuts its silhouette in half
    edge = _silhouette(truck_c, truck, T_cw, K)[:, 0].max()
    lo, hi = -3.0, 3.0
    for _ in range(60):
        y = (lo + hi) / 2
        a, poly = hull_area(_silhouette(hidden_c + [0, y, 0], car, T_cw, K))
        share = area_right_of(poly, edge) / a
        lo, hi = (y, hi) if share > 0.5 else (lo, y)   # more y: further left in the image, more hidden
    hidden_c = hidden_c + [0, (lo + hi) / 2, 0]
    a, poly = hull_area(_silhouette(hidden_c, car, T_cw, K))
    hidden_share = area_right_of(poly, edge) / a
    # a car at 12 m whose left part leaves the image (world +y is image left)
    cut_c = np.array([12.0, 12.0 * np.tan(np.radians(hfov / 2)) + 0.3, car[2] / 2])
    a, poly = hull_area(_silhouette(cut_c, car, T_cw, K))
    cut_trunc = 1.0 - area_right_of(poly, 0.0) / a
    parts = [("ground", M.rect(-10, -40, 80, 40, 0.0, "road", "asphalt"), np.eye(4), 0),
             ("truck", M.box(truck, "truck", "truck_paint"), M.pose(*truck_c), TRUCK),
             ("hidden", M.box(car, "car", "car_paint"), M.pose(*hidden_c), HIDDEN),
             ("cut", M.box(car, "car", "car_paint"), M.pose(*cut_c), CUT)]
    return BoxScene(make_scene(parts), T_wc, K, hidden_share, cut_trunc)


def instance_pass(scene, T_world_camera: np.ndarray, K: np.ndarray, width: int, height: int) -> np.ndarray:
    """(H, W) uint32 instance id of the first surface on each pixel-centre ray (Embree), what a 1-sample
    label pass holds."""
    from generator.lidar.caster import EmbreeCaster

    d = rig.pixel_rays(K, width, height).reshape(-1, 3) @ np.asarray(T_world_camera)[:3, :3].T
    o = np.broadcast_to(np.asarray(T_world_camera)[:3, 3], d.shape)
    _, prim = EmbreeCaster.from_scene(scene).intersect(o, d, 1000.0)
    inst = np.where(prim >= 0, scene.face_instance[np.maximum(prim, 0)], 0)
    return inst.reshape(height, width).astype(np.uint32)
