"""A pixel's owner is the actor its surface point belongs to, whatever a supersampled label vote says."""

from __future__ import annotations

import numpy as np

from generator.motion.owners import _dilate, pixel_owners
from generator.world import rig
from generator.world.kinematics import movers
from kits import motion_kit as mk

W, H = 160, 96
K = rig.intrinsics(90.0, W, H)


def test_owner_follows_the_surface_not_a_label_vote_on_the_silhouette():
    """With ``label_supersample`` the label pass's majority vote may give a silhouette pixel to the car
    while its centre ray (the depth) passes the car, or the reverse; the owner is the real surface's."""
    crossing = mk.car(0, 301, mk.track(lambda t: (12.0, -6.0 + 8.0 * t)))
    w = mk.world(mk.street_scene(), [crossing], mk.track(lambda t: (0.0, 0.0)))
    T = w.ego.T_world_ego(1.0)[0] @ rig.camera_extrinsics((0.0, 0.0, 1.2), (0.0, 0.0, 0.0))
    view, _ = mk.Caster(w).view(T, K, W, H, 1.0)
    X = rig.pixel_rays(K, W, H) * np.where(np.isfinite(view.depth), view.depth, 0.0)[..., None]
    Xw = X @ T[:3, :3].T + T[:3, 3]
    known = np.isfinite(view.depth)
    ms = movers(w, 1.0, 1.1)
    car = view.instance == 301
    truth = pixel_owners(Xw, known, view.instance, ms)
    assert (truth == np.where(car, 0, -1)).all()  # labels and depth agree: the owner is the label
    grown = np.where(_dilate(car), 301, view.instance)  # the vote gave the car one more pixel all round
    shrunk = np.where(car & ~_dilate(~car), 301, np.where(car, 0, view.instance))  # ... or one less
    assert (grown != view.instance).sum() > 20 and (shrunk != view.instance).sum() > 20
    assert (pixel_owners(Xw, known, grown, ms) == truth).all()
    assert (pixel_owners(Xw, known, shrunk, ms) == truth).all()


def test_road_under_a_car_stays_road_unless_labelled_with_it():
    """A ground point inside the car's footprint but not labelled with the car keeps still."""
    a = mk.car(0, 301, mk.track(lambda t: (0.0, 0.0)))
    ms = movers(mk.world(mk.street_scene(), [a], mk.track(lambda t: (0.0, 0.0))), 0.0, 1.0)
    pts = np.array([[[1.0, 0.2, 0.0], [1.0, 0.2, 0.6]]])  # road under the car, a point on its body
    assert (pixel_owners(pts, np.ones((1, 2), bool), np.zeros((1, 2), np.uint32) + [301, 0], ms) == [[0, 0]]).all()
    assert (pixel_owners(pts, np.ones((1, 2), bool), np.array([[0, 301]], np.uint32), ms) == [[-1, 0]]).all()
