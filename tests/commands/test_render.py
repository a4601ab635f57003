"""`urbangen render` end to end on the test town at the test preset (Blender).

One frame in all 12 weather x time-of-day variants, rendered once per test run (:mod:`kits.rendered_frame`,
shared with the sky and camera-model tests).
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from generator.imaging.exr import read_exr
from generator.imaging.paths import image_dir
from generator.labels import class_table
from generator.previews.preview import tonemap
from generator.weather import combinations
from kits.rendered_frame import FRAME, all_variants, second_render

pytestmark = pytest.mark.blender


@pytest.fixture(scope="module")
def rendered(tmp_path_factory, root):
    return image_dir(all_variants(tmp_path_factory, root).path(), FRAME)


def _load(images, tod, kind):
    name = f"{FRAME:06d}_{tod}_{kind}"
    return read_exr(images / f"{name}.exr"), json.loads((images / f"{name}.json").read_text())


def test_twelve_images_with_every_channel(rendered):
    names = sorted(p.stem for p in rendered.glob("*.exr"))
    assert names == sorted(f"{FRAME:06d}_{t}_{k}" for t, k in combinations())
    assert len(list(rendered.glob("*_preview.png"))) == 12
    assert not list(rendered.glob(".tmp-*"))


@pytest.mark.parametrize("tod,kind", combinations())
def test_masks_partition_and_metadata_agrees(rendered, tod, kind):
    img, meta = _load(rendered, tod, kind)  # read_exr already rejects non-binary / non-partitioning masks
    present = {class_table().names[c]: int(n) for c, n in enumerate(np.bincount(img.class_id.ravel())) if n}
    assert meta["classes_present"] == present
    assert meta["weather"]["kind"] == kind and meta["time_of_day"] == tod
    assert meta["seed"] == 7 and len(meta["spec_hash"]) == 64


def test_variants_share_masks_and_depth(rendered):
    ref, _ = _load(rendered, "day", "clear")
    for tod, kind in combinations():
        img, _ = _load(rendered, tod, kind)
        assert np.array_equal(img.class_id, ref.class_id)
        assert np.array_equal(img.instance, ref.instance)
        assert np.array_equal(img.depth, ref.depth)


def test_fog_and_rain_change_only_rgb(rendered):
    clear, _ = _load(rendered, "day", "clear")
    wet, _ = _load(rendered, "day", "wet")
    for kind, base in (("fog", clear), ("rain", wet), ("rain_fog", wet), ("wet_fog", wet)):
        img, meta = _load(rendered, "day", kind)
        assert np.abs(img.rgb - base.rgb).mean() > 1e-3, kind
    _, fog_meta = _load(rendered, "day", "fog")
    w = fog_meta["weather"]
    assert w["beta_per_m"] == pytest.approx(3.912 / w["visibility_m"])


def test_night_is_darker_and_lamps_are_on(rendered):
    day, dmeta = _load(rendered, "day", "clear")
    night, nmeta = _load(rendered, "night", "clear")
    assert tonemap(night.rgb).mean() < 0.6 * tonemap(day.rgb).mean()
    assert "street_lamps" in nmeta["lighting"]["light_groups_on"]
    assert "street_lamps" not in dmeta["lighting"]["light_groups_on"]
    assert dmeta["lighting"]["sun_elevation_deg"] is not None


def test_exr_opens_in_blender(rendered):
    """Blender reads the file as a multilayer image: RGB, depth and instance passes, one pass per mask."""
    from generator.blender.bpy_guard import bpy

    path = rendered / f"{FRAME:06d}_day_clear.exr"
    img = bpy.data.images.load(str(path))
    tree = bpy.data.node_groups.new("exr_check", "CompositorNodeTree")
    try:
        node = tree.nodes.new("CompositorNodeImage")
        node.image = img  # loads the file
        assert img.type == "MULTILAYER"
        default = {o.name for o in node.outputs if o.enabled}
        assert {"Combined", "depth", "instance"} <= default
        node.layer = "mask"
        assert {o.name for o in node.outputs if o.enabled} == set(class_table().names)
    finally:
        bpy.data.node_groups.remove(tree)
        bpy.data.images.remove(img)


def test_second_render_gives_identical_masks(rendered, tmp_path_factory, root):
    """A second run of two variants (shared with tests/blender/test_skies.py, which compares its RGB)."""
    again = image_dir(second_render(tmp_path_factory, root).path(), FRAME)
    for tod in ("day", "night"):
        a, _ = _load(rendered, tod, "clear")
        b, _ = _load(again, tod, "clear")
        assert np.array_equal(a.class_id, b.class_id) and np.array_equal(a.depth, b.depth)
