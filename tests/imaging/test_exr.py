"""The dataset EXR: round-trips, holds every mask channel, opens in OpenImageIO, rejects broken files."""

from __future__ import annotations

import numpy as np
import OpenEXR
import pytest

from generator.errors import UserError
from generator.imaging.exr import LabelledImage, mask_channel, read_exr, write_exr
from generator.imaging.metadata import camera_angles, class_pixels
from generator.labels import class_table
from generator.previews.preview import tonemap, write_preview


@pytest.fixture
def image(rng):
    h, w = 24, 32
    cls = rng.integers(0, len(class_table()), (h, w)).astype(np.uint8)
    depth = rng.uniform(1, 100, (h, w)).astype(np.float32)
    depth[cls == class_table().id("sky")] = np.inf
    return LabelledImage(rng.uniform(0, 4, (h, w, 3)).astype(np.float32), cls,
                         rng.integers(0, 70000, (h, w)).astype(np.uint32), depth, {"urbangen.image": "x"})


def test_round_trip(tmp_path, image):
    p = tmp_path / "a.exr"
    write_exr(p, image)
    back = read_exr(p)
    assert np.array_equal(back.class_id, image.class_id)
    assert np.array_equal(back.instance, image.instance)
    assert np.array_equal(back.depth, image.depth)
    assert np.allclose(back.rgb, image.rgb, rtol=1e-3)
    assert back.header["urbangen.classes"].split(",") == class_table().names
    assert not list(tmp_path.glob(".tmp-*"))


def test_layout_types_and_compression(tmp_path, image):
    p = tmp_path / "a.exr"
    write_exr(p, image)
    with OpenEXR.File(str(p), separate_channels=True) as f:
        ch = {k: v for k, v in f.channels().items()}
        assert f.header()["compression"] == OpenEXR.ZIP_COMPRESSION
    assert {mask_channel(n) for n in class_table().names} <= set(ch)
    assert ch["R"].pixels.dtype == np.float16 and ch["mask.road.V"].pixels.dtype == np.float16
    assert ch["depth.Z"].pixels.dtype == np.float32 and ch["instance.id"].pixels.dtype == np.uint32
    masks = np.stack([ch[mask_channel(n)].pixels for n in class_table().names]).astype(np.float32)
    assert set(np.unique(masks)) <= {0.0, 1.0}
    assert (masks.sum(0) == 1).all()


def test_opens_in_openimageio(tmp_path, image):
    oiio = pytest.importorskip("OpenImageIO")
    p = tmp_path / "a.exr"
    write_exr(p, image)
    inp = oiio.ImageInput.open(str(p))
    spec = inp.spec()
    names = list(spec.channelnames)
    assert names[:3] == ["R", "G", "B"]
    assert all(mask_channel(n) in names for n in class_table().names)
    assert spec.getattribute("urbangen.classes") == ",".join(class_table().names)
    pixels = inp.read_image(0, 0, 0, spec.nchannels, "float")
    inp.close()
    road = pixels[..., names.index("mask.road.V")]
    assert np.array_equal(road == 1.0, image.class_id == class_table().id("road"))


def _tamper(src, dst, fn):
    with OpenEXR.File(str(src), separate_channels=True) as f:
        header = {k: v for k, v in f.header().items() if k in ("compression", "type") or k.startswith("urbangen.")}
        ch = {k: v.pixels.copy() for k, v in f.channels().items()}
    fn(ch)
    with OpenEXR.File(header, ch) as f:
        f.write(str(dst))


@pytest.mark.parametrize("fault,message", [
    (lambda ch: ch.pop("mask.car.V"), "missing channel(s) mask.car"),
    (lambda ch: ch["mask.road.V"].__setitem__((0, 0), 0.5), "not binary"),
    (lambda ch: ch["mask.road.V"].__setitem__((slice(None), slice(None)), 1.0), "do not partition"),
])
def test_reader_catches_faults(tmp_path, image, fault, message):
    write_exr(tmp_path / "a.exr", image)
    _tamper(tmp_path / "a.exr", tmp_path / "b.exr", fault)
    with pytest.raises(UserError, match=message.replace("(", r"\(").replace(")", r"\)")):
        read_exr(tmp_path / "b.exr")


def test_not_an_exr(tmp_path):
    p = tmp_path / "x.exr"
    p.write_bytes(b"not an exr")
    with pytest.raises(UserError, match="cannot read as EXR"):
        read_exr(p)


def test_class_pixels_sum_to_image(image):
    counts = class_pixels(image.class_id)
    assert sum(counts.values()) == image.class_id.size
    assert all(v > 0 for v in counts.values())


def test_camera_angles():
    from generator.world import rig

    t = rig.ego_pose(np.zeros(3), np.radians(30)) @ rig.camera_extrinsics((0, 0, 1.6), (0, 0, 0),
                                                                          np.radians([10, -5, 4]))
    a = camera_angles(t)
    assert a["yaw"] == pytest.approx(40.0, abs=0.2)
    assert a["pitch"] == pytest.approx(5.0, abs=0.2)  # body pitch -5 deg about y looks up
    assert abs(a["tilt"]) == pytest.approx(4.0, abs=0.2)


def test_preview_png(tmp_path, image):
    from PIL import Image

    write_preview(tmp_path / "p.png", image.rgb, image.class_id, image.depth)
    im = Image.open(tmp_path / "p.png")
    assert im.size[0] == 3 * 32 + 2 * 4 and im.size[1] > 24
    assert tonemap(np.zeros((1, 1, 3)))[0, 0].tolist() == [0, 0, 0]
