"""The camera streams of a dataset, as the motion ground truth reads them (:mod:`generator.jobs.motion`).

Two kinds of stream:

* **images/** -- the seed-003 frames of a town's drive. Consecutive frames of one weather x time
  variant form a stream; every variant of a frame shares its masks, depth and camera pose (only
  the RGB differs), so one flow per frame serves them all. The *next image* of frame ``k``'s
  stream is the next frame of the same town that has images (``k + 1`` in a finished dataset,
  ``paths.spacing_m`` further along the route); a town's last frame has no forward flow, its
  first no backward one. Frames are read through one variant each (``day_clear`` if present).
* **KITTI stream** -- ``sequences/NN/image_2`` and ``image_3``, a stereo pair every
  ``sensors.stereo.every``-th sweep; the next image of ``image_2/NNNNNN`` is the next pair's
  ``image_2`` (the next sweep with ``passes_2``).

Only what a flow needs is read: each image's depth and instance channels, exposure time,
intrinsics and camera pose. A stream whose images lack the depth or instance pass is refused
(one line naming the file).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from generator.errors import SpecError, UserError
from generator.imaging import meta_fields as md
from generator.imaging.exr import channel_names, read_channels
from generator.motion.optical_flow import View
from generator.safeload import printable

#: The channels a flow reads from an image's EXR.
PASSES = ("depth.Z", "instance.id")
#: The variant a frame of images/ is read through when it has it.
PREFERRED_VARIANT = "day_clear"


@dataclass(frozen=True)
class StreamImage:
    """One image of a stream.

    Attributes
    ----------
    name : str
        ``000003`` (a frame of images/) or ``000010`` (a sweep of the KITTI stream).
    exr, meta : Path
        Its EXR (depth, instances) and metadata JSON.
    t : float
        Exposure time on the drive's timeline, seconds.
    K : (3, 3) float64
    T_world_camera : (4, 4) float64
    width, height : int
        Image size its metadata gives, pixels.
    """

    name: str
    exr: Path
    meta: Path
    t: float
    K: np.ndarray
    T_world_camera: np.ndarray
    width: int
    height: int

    def view(self) -> View:
        """The image's depth and instances with its camera (:class:`generator.motion.optical_flow.View`)."""
        ch, _ = read_channels(self.exr, list(PASSES))
        depth = np.asarray(ch["depth.Z"], np.float32)
        inst = ch["instance.id"]
        if inst.dtype.kind not in "iu":
            raise UserError(f"{printable(self.exr)}: channel instance.id must be UINT")
        if depth.shape != (self.height, self.width):
            raise UserError(f"{printable(self.exr)}: {depth.shape[1]}x{depth.shape[0]} pixels but its metadata "
                            f"{printable(self.meta.name)} says {self.width}x{self.height}")
        return View(depth, inst, self.K, self.T_world_camera, self.t)


def check_passes(images: list[StreamImage]) -> None:
    """Refuse (one line) an image whose EXR has no depth or instance pass."""
    for img in images:
        have = set(channel_names(img.exr))
        missing = [c for c in PASSES if c not in have]
        if missing:
            raise UserError(f"{printable(img.exr)}: no {' or '.join(missing)} channel: optical flow and disparity "
                            "need the depth and instance passes of every image")


def _time(doc: dict, key: str, src: str) -> float:
    v = md.field(doc, key, src)
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not np.isfinite(v):
        raise SpecError(src, key, "must be a number of seconds")
    return float(v)


def _pose(doc: dict, key: str, src: str) -> np.ndarray:
    T = md.matrix(doc, key, (4, 4), src)
    problem = md.rigid_problem(T)
    if problem:
        raise SpecError(src, key, problem)
    return T


def frame_images(ds) -> dict[int, str]:
    """Frame -> the image name it is read through (``day_clear`` if present), over ``ds.image_names()``."""
    out: dict[int, str] = {}
    for name in ds.image_names():
        k = int(name[:6])
        if k not in out or name[7:] == PREFERRED_VARIANT:
            out[k] = name
    return out


def images_stream(ds, frames=None) -> list[StreamImage]:
    """The frames of ``images/`` (each through one variant, in frame order), optionally only ``frames``.

    Parameters
    ----------
    ds : generator.dataset.Dataset
    frames : iterable of int, optional
        Keep only these frames (one town's).
    """
    out = []
    for k, name in sorted(frame_images(ds).items()):
        if frames is not None and k not in frames:
            continue
        exr, meta = ds.image_files(name)
        src = str(meta)
        doc = md.load_metadata(meta)
        K, w, h = md.intrinsics(doc, src)
        out.append(StreamImage(f"{k:06d}", exr, meta, _time(doc, "time_s", src), K,
                               _pose(doc, "camera.T_world_camera", src), w, h))
    return out


def stereo_stream(seq_dir: Path, camera: int) -> list[StreamImage]:
    """The images of camera ``camera`` (2 or 3) of a sequence's KITTI stream, in sweep order."""
    folder = Path(seq_dir) / f"passes_{camera}"
    if not folder.is_dir():
        return []
    out = []
    for meta in sorted(folder.glob("[0-9][0-9][0-9][0-9][0-9][0-9].json")):
        exr = meta.with_suffix(".exr")
        if not os.path.lexists(exr):
            continue
        src = str(meta)
        doc = md.load_metadata(meta)
        K = md.matrix(doc, "K", (3, 3), src)
        w = md.integer(doc, "width", src, 1, md.MAX_IMAGE_SIDE)
        h = md.integer(doc, "height", src, 1, md.MAX_IMAGE_SIDE)
        if not (K[0, 0] > 0 and K[1, 1] > 0 and K[1, 0] == 0 and np.array_equal(K[2], [0.0, 0.0, 1.0])):
            raise SpecError(src, "K", "must be a pinhole matrix [[fx, s, cx], [0, fy, cy], [0, 0, 1]] with fx, fy > 0")
        out.append(StreamImage(meta.stem, exr, meta, _time(doc, "time_s", src), K, _pose(doc, "T_world_camera", src),
                               w, h))
    return out
