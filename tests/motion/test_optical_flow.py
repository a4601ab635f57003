"""Optical flow from depth, instances and poses: analytic cases, label warping, forward-backward consistency.

Images are ray-cast (``kits.motion_kit``): depth, class and instance of the surface each pixel
centre sees, as the real pass renders them.
"""

from __future__ import annotations

import numpy as np
import pytest

from generator.fusion.projection import boundary_mask
from generator.motion.optical_flow import ACTOR, KNOWN, VISIBLE, optical_flow
from generator.world import rig
from generator.world.kinematics import movers
from kits import motion_kit as mk

W, H = 160, 96
K = rig.intrinsics(90.0, W, H)
T_EGO_CAM = rig.camera_extrinsics((0.0, 0.0, 1.65), (0.0, 0.0, 0.0))


@pytest.fixture(scope="module")
def street():
    """Ego still at the origin; a car crossing 20 m ahead at 10 m/s (towards +y, the image's left)."""
    crossing = mk.car(0, 301, mk.track(lambda t: (20.0, -12.0 + 10.0 * t)))
    w = mk.world(mk.street_scene(), [crossing], mk.track(lambda t: (0.0, 0.0)))
    return w, mk.Caster(w)


def _flow(w, caster, t0, t1, T0=None, T1=None):
    T0 = w.ego.T_world_ego(t0)[0] @ T_EGO_CAM if T0 is None else T0
    T1 = w.ego.T_world_ego(t1)[0] @ T_EGO_CAM if T1 is None else T1
    (a, cls_a), (b, cls_b) = caster.view(T0, K, W, H, t0), caster.view(T1, K, W, H, t1)
    return a, b, cls_a, cls_b, optical_flow(a, b, movers(w, t0, t1))


def test_crossing_car_has_the_analytic_flow(street):
    """Camera still, the car's side face (fronto-parallel, 19.1 m ahead of the axle line) moves
    10 m/s x 0.05 s to the left: u = -fx v dt / Z on every pixel of that face, v = 0; the town does not move."""
    w, caster = street
    t0, dt = 1.2, 0.05
    a, _, _, _, f = _flow(w, caster, t0, t0 + dt)
    Z = a.depth * mk.rig.pixel_rays(K, W, H)[..., 2]
    face = (a.instance == 301) & (np.abs(Z - (20.0 - 0.9)) < 1e-3)
    assert face.sum() > 100
    assert ((f.flags[face] & (KNOWN | ACTOR)) == KNOWN | ACTOR).all()
    expected_u = -K[0, 0] * 10.0 * dt / (20.0 - 0.9)
    np.testing.assert_allclose(f.uv[face, 0], expected_u, atol=2e-3)
    np.testing.assert_allclose(f.uv[face, 1], 0.0, atol=2e-3)
    static = f.known & (a.instance != 301)
    assert np.abs(f.uv[static]).max() < 1e-3
    assert not (f.flags[static] & ACTOR).any()


def test_ego_driving_at_a_wall_has_the_analytic_flow():
    """Ego at 10 m/s towards the end wall (fronto-parallel, D ahead): a wall pixel at (x, y) from the
    principal point moves to (x, y) D / (D - s), s = the distance driven."""
    w = mk.world(mk.street_scene(), [], mk.track(lambda t: (10.0 * t, 0.0)))
    caster = mk.Caster(w)
    t0, dt = 1.0, 0.1
    a, _, _, _, f = _flow(w, caster, t0, t0 + dt)
    Z = a.depth * rig.pixel_rays(K, W, H)[..., 2]
    D = 89.0 - 10.0 * t0
    wall = np.abs(Z - D) < 1e-3
    assert wall.sum() > 200
    uc, vc = np.meshgrid(np.arange(W) + 0.5 - K[0, 2], np.arange(H) + 0.5 - K[1, 2])
    s = 10.0 * dt
    np.testing.assert_allclose(f.uv[wall, 0], uc[wall] * s / (D - s), atol=2e-3)
    np.testing.assert_allclose(f.uv[wall, 1], vc[wall] * s / (D - s), atol=2e-3)
    assert f.visible[wall].mean() > 0.95


@pytest.fixture(scope="module")
def town(test_scene):
    """The test town with the ego and two cars driving its route (the ego at 8 m/s, the cars ahead)."""
    path = test_scene.paths[0]

    def along(s0, v):
        return lambda t: tuple(path.at(s0 + v * t)[0][0, :2])

    cars = [mk.car(0, 401, mk.track(along(14.0, 6.0), 6.0)), mk.car(1, 402, mk.track(along(30.0, 9.0), 6.0))]
    w = mk.world(test_scene, cars, mk.track(along(0.0, 8.0), 6.0), 6.0)
    return w, mk.Caster(w)


def _camera(w, t, jitter):
    return w.ego.T_world_ego(t)[0] @ rig.camera_extrinsics((0.0, 0.0, 1.65), (0.0, 0.0, 0.0), jitter)


def _warp(labels_b, flow, shape):
    h, wd = shape
    uc, vc = np.meshgrid(np.arange(wd) + 0.5, np.arange(h) + 0.5)
    col = np.clip(np.floor(uc + flow.uv[..., 0]).astype(int), 0, wd - 1)
    row = np.clip(np.floor(vc + flow.uv[..., 1]).astype(int), 0, h - 1)
    return labels_b[row, col], row, col


@pytest.mark.parametrize("t0, t1", [(2.0, 2.1), (2.0, 3.0), (3.0, 2.5)])
def test_warping_the_next_labels_with_the_flow_gives_these_labels(town, t0, t1):
    """Frame B's class and instance maps, sampled where the flow sends each pixel of A, are A's own on
    >= 99.5 % of A's visible pixels away from label boundaries (in A and where they land in B)."""
    w, caster = town
    T0, T1 = _camera(w, t0, (0.1, 0.0, 0.05)), _camera(w, t1, (-0.15, 0.03, -0.02))
    a, b, cls_a, cls_b, f = _flow(w, caster, t0, t1, T0, T1)
    warped_cls, row, col = _warp(cls_b, f, a.shape)
    warped_inst, _, _ = _warp(b.instance, f, a.shape)
    edge_b = boundary_mask(cls_b) | boundary_mask(b.instance)
    keep = f.visible & ~boundary_mask(cls_a) & ~boundary_mask(a.instance) & ~edge_b[row, col]
    assert keep.sum() > 1000
    assert (warped_cls == cls_a)[keep].mean() >= 0.995
    assert (warped_inst == a.instance)[keep].mean() >= 0.995
    moving = keep & np.isin(a.instance, [401, 402])
    if moving.any():  # the actors' own pixels warp as well as the town's
        assert (warped_inst == a.instance)[moving].mean() >= 0.995


def test_forward_and_backward_flow_are_consistent(town):
    """Following the forward flow and then the backward flow (bilinear) comes back within 0.5 px on every
    visible pixel whose landing cell in B lies on one surface."""
    w, caster = town
    t0, t1 = 2.0, 2.3
    T0, T1 = _camera(w, t0, (0.1, 0.0, 0.05)), _camera(w, t1, (-0.05, 0.02, 0.0))
    a, b, cls_a, cls_b, fw = _flow(w, caster, t0, t1, T0, T1)
    bw = optical_flow(b, a, movers(w, t1, t0))
    h, wd = a.shape
    uc, vc = np.meshgrid(np.arange(wd) + 0.5, np.arange(h) + 0.5)
    x, y = uc + fw.uv[..., 0] - 0.5, vc + fw.uv[..., 1] - 0.5  # pixel-centre grid coordinates in B
    x0, y0 = np.floor(x).astype(int), np.floor(y).astype(int)
    inside = fw.visible & (x0 >= 0) & (y0 >= 0) & (x0 < wd - 1) & (y0 < h - 1)
    x0c, y0c = np.clip(x0, 0, wd - 2), np.clip(y0, 0, h - 2)
    corners = [(y0c + dy, x0c + dx) for dy in (0, 1) for dx in (0, 1)]
    one_surface = inside & ~boundary_mask(cls_a) & ~boundary_mask(a.instance)
    for r, c in corners:
        one_surface &= bw.visible[r, c] & (b.instance[r, c] == a.instance) & (cls_b[r, c] == cls_a)
    fx, fy = x - x0c, y - y0c
    wts = [(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy]
    back = sum(wt[..., None] * bw.uv[r, c] for wt, (r, c) in zip(wts, corners, strict=True))
    err = np.linalg.norm(fw.uv + back, axis=-1)[one_surface]
    assert one_surface.sum() > 1000
    assert err.max() <= 0.5, np.percentile(err, [50, 99, 100])


def test_points_behind_the_camera_or_sky_have_no_flow(street):
    w, caster = street
    a, _, _, _, f = _flow(w, caster, 1.0, 1.1)
    sky = ~np.isfinite(a.depth)
    assert sky.any() and not f.flags[sky].any() and not f.uv[sky].any()
    assert ((f.flags & VISIBLE) <= (f.flags & KNOWN) * 2).all()  # visible implies known
