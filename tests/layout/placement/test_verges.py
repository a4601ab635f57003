"""Verge crossings (issue 27, other-ground on the streets a drive passes): paved hard-standing
across a grass verge in front of building lots, lying on the verge between its kerbs, the
greenery round it."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from generator.geometry import apply
from generator.labels import class_table
from generator.layout import build_scene
from generator.layout.network.draw import make_grid
from generator.layout.network.grid import segment_frame_points
from generator.spec import parse_spec
from kits.town_checks import no_collisions, rests_on_ground


def _spec(root, driveways: float, blocks: int = 2):
    doc = json.loads((root / "scenes" / "kitti_like.json").read_text())
    doc["town"].update(blocks_x=blocks, blocks_y=blocks)
    doc["density"]["driveways"] = driveways
    return parse_spec(doc, "kitti_like.json")


@pytest.fixture(scope="module")
def town(root):
    spec = _spec(root, 1.0)
    return spec, make_grid(spec), build_scene(spec)


def test_crossings_lie_on_verges_between_their_kerbs(town):
    spec, grid, scene = town
    crossings = [o for o in scene.objects if o.kind == "verge_crossing"]
    assert len(crossings) >= 8
    other = class_table().id("other_ground")
    h = spec.town.curb_height_m
    verges = [(seg, s) for seg in grid.segments if grid.strip_span(seg) for s in (-1, 1)
              if grid.section(seg).strip(s) == "verge"]
    for o in crossings:
        m = scene.prototypes[o.prototype]
        assert (m.face_class == other).all(), o.name
        world = apply(o.transform, m.vertices.astype(np.float64))
        # stands 2 cm proud of the grass, sunk 5 mm into it
        assert world[:, 2].max() == pytest.approx(h + 0.02, abs=1e-4), o.name
        assert world[:, 2].min() == pytest.approx(h - 0.005, abs=1e-4), o.name
        on = []
        for seg, s in verges:
            uv = segment_frame_points(seg, world[:, :2])
            u0, u1 = grid.strip_span(seg)
            v = s * uv[:, 1]
            if ((v > grid.lane_half + grid.curb_w - 1e-6) & (v < grid.road_half + 1e-6)).all() \
                    and (uv[:, 0] > u0).all() and (uv[:, 0] < u1).all():
                on.append(seg.index)
                # across the whole grass strip, kerb to sidewalk
                assert v.min() == pytest.approx(grid.lane_half + grid.curb_w, abs=1e-6)
                assert v.max() == pytest.approx(grid.road_half, abs=1e-6)
        assert len(on) == 1, o.name


def test_greenery_leaves_the_crossings_free(town):
    spec, grid, scene = town
    no_collisions(scene)
    rests_on_ground(spec, grid, scene)
    # hedge pieces were cut round the crossings, not dropped: the hedges of the verges still cover
    # most of the residential verge length
    plain = build_scene(_spec_with(spec, driveways=0.0))
    hedges = sum(np.ptp(plain.prototypes[o.prototype].vertices[:, 0]) for o in plain.objects if o.kind == "hedge")
    cut = sum(np.ptp(scene.prototypes[o.prototype].vertices[:, 0]) for o in scene.objects if o.kind == "hedge")
    n = sum(o.kind == "verge_crossing" for o in scene.objects)
    assert not any(o.kind == "verge_crossing" for o in plain.objects)
    assert hedges - cut <= n * (4.5 + 2 * 0.3 + 1.0) + 1e-6
    assert cut > 0.8 * hedges


def _spec_with(spec, **density):
    return dataclasses.replace(spec, density=dataclasses.replace(spec.density, **density))
