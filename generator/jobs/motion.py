"""Write a dataset's optical flow and stereo disparity (:mod:`generator.motion`), after its images exist.

A cheap numpy step run by ``generate`` once a town's images and stereo pairs are rendered (and by
``urbangen flow`` on an existing dataset): per stream (:mod:`generator.jobs.motion_streams`) each
image's forward flow to the next image and backward flow to the previous one, from the depth
and instance passes already written, the camera poses of their metadata and the actors' poses of
the world in time. No render, no ray cast. Files (KITTI PNGs: :mod:`generator.formats.kitti_flow`;
float EXRs: :mod:`generator.imaging.motion_exr`):

======================================  ========================================================
``flow/NNNNNN.exr``                     frame ``NNNNNN`` of images/ (every variant): forward and
                                        backward flow, float, with their masks
``flow/flow_occ|flow_noc/NNNNNN.png``   its forward flow, KITTI: every known pixel | only pixels
                                        visible in the next image
``sequences/NN/flow_2|flow_3/NNNNNN.exr``  the same for ``image_2|3/NNNNNN`` of the KITTI stream
``sequences/NN/flow_occ|flow_noc/``     ``image_2``'s forward flow, KITTI (``flow_occ_3|flow_noc_3/``:
                                        ``image_3``'s)
``sequences/NN/disp_occ_0|disp_noc_0/`` KITTI stereo 2015 disparity of ``image_2/NNNNNN``: every
                                        pixel with a surface | only those the right camera sees
``sequences/NN/disp_2/NNNNNN.exr``      the disparity as float with its mask
======================================  ========================================================
"""

from __future__ import annotations

import logging
import time
from pathlib import Path

from generator.formats.kitti_flow import write_disparity_png, write_flow_png
from generator.imaging.motion_exr import write_disparity_exr, write_flow_exr
from generator.jobs.motion_streams import StreamImage, check_passes, images_stream, stereo_stream
from generator.motion.disparity import disparity
from generator.motion.optical_flow import KNOWN, VISIBLE, optical_flow
from generator.world.kinematics import movers

log = logging.getLogger(__name__)

#: Folders of the images/ stream's flows, under the dataset root.
IMAGES_FLOW = "flow"
#: (float EXR, KITTI flow_occ, KITTI flow_noc) folders of each KITTI-stream camera, in ``sequences/NN``.
STEREO_FLOW = {2: ("flow_2", "flow_occ", "flow_noc"), 3: ("flow_3", "flow_occ_3", "flow_noc_3")}
#: (float EXR, KITTI disp_occ, KITTI disp_noc) folders of the left camera's disparity.
DISPARITY = ("disp_2", "disp_occ_0", "disp_noc_0")


def write_stream(images: list[StreamImage], world, folders: tuple[Path, Path, Path], image_prefix: str = "",
                 codec: str = "zip") -> dict:
    """Forward and backward flow of every image of one stream.

    Parameters
    ----------
    images : list of StreamImage
        The stream, in order.
    world : generator.world.actors.World or None
        The actors' motion (None: a frozen town).
    folders : (Path, Path, Path)
        Float EXR, KITTI ``flow_occ`` and ``flow_noc`` folders.
    image_prefix : str
        Prefix of the image names recorded in the EXR header (``image_2/``).

    Returns
    -------
    dict
        ``images``, ``seconds`` and the share of pixels known / visible over the forward flows.
    """
    t0 = time.perf_counter()
    floats, occ, noc = folders
    views: dict[int, object] = {}
    known = visible = pixels = 0
    for i, img in enumerate(images):
        for j in (i - 1, i, i + 1):
            if 0 <= j < len(images) and j not in views:
                views[j] = images[j].view()
        views.pop(i - 2, None)
        flows, to = {}, {}
        for d, j in (("forward", i + 1), ("backward", i - 1)):
            if 0 <= j < len(images):
                flows[d] = optical_flow(views[i], views[j], movers(world, img.t, images[j].t))
                to[d] = image_prefix + images[j].name
        if not flows:
            continue
        write_flow_exr(floats / f"{img.name}.exr", image_prefix + img.name, flows, to, codec)
        if "forward" in flows:
            f = flows["forward"]
            write_flow_png(occ / f"{img.name}.png", f.uv, (f.flags & KNOWN) > 0)
            write_flow_png(noc / f"{img.name}.png", f.uv, (f.flags & VISIBLE) > 0)
            known += int(f.known.sum())
            visible += int(f.visible.sum())
            pixels += f.flags.size
    return {"images": len(images), "seconds": round(time.perf_counter() - t0, 3),
            "forward_known": round(known / pixels, 4) if pixels else None,
            "forward_visible": round(visible / pixels, 4) if pixels else None}


def write_disparities(seq_dir: Path, codec: str = "zip", out_dir: Path | None = None) -> dict:
    """KITTI stereo 2015 disparity of every stereo pair of ``seq_dir`` (and the float file), into
    ``out_dir`` (default ``seq_dir``)."""
    t0 = time.perf_counter()
    left = {img.name: img for img in stereo_stream(seq_dir, 2)}
    right = {img.name: img for img in stereo_stream(seq_dir, 3)}
    floats, occ, noc = (Path(seq_dir if out_dir is None else out_dir) / f for f in DISPARITY)
    n = 0
    for name in sorted(set(left) & set(right)):
        d, flags = disparity(left[name].view(), right[name].view())
        write_disparity_exr(floats / f"{name}.exr", f"image_2/{name}", d, flags, codec)
        write_disparity_png(occ / f"{name}.png", d, (flags & KNOWN) > 0)
        write_disparity_png(noc / f"{name}.png", d, (flags & VISIBLE) > 0)
        n += 1
    return {"pairs": n, "seconds": round(time.perf_counter() - t0, 3)}


def stereo_images(seq_dir: Path) -> dict[int, list[StreamImage]]:
    """Camera -> its KITTI-stream images in ``seq_dir`` (empty lists without a stream)."""
    return {cam: stereo_stream(seq_dir, cam) for cam in STEREO_FLOW}


def write_motion(ds, world, frames=None, sequence: str | None = None, codec: str = "zip",
                 out: Path | None = None) -> dict:
    """Optical flow of the images/ frames ``frames`` (one town's) and of ``sequence``'s KITTI stream, and
    the stream's disparity (see the module docstring); a stream of one image gets none.

    Parameters
    ----------
    ds : generator.dataset.Dataset
        The dataset (how its images are found).
    world : generator.world.actors.World or None
        The town's world in time.
    frames : iterable of int, optional
        The town's frames (default: every frame of images/).
    sequence : str, optional
        The town's LiDAR sequence ``NN`` (None: no KITTI stream).
    out : Path, optional
        Root the files go under, in the dataset's layout (default: the dataset itself).
    """
    root = Path(ds.root)
    out = root if out is None else Path(out)
    record = {}
    imgs = images_stream(ds, None if frames is None else set(frames))
    check_passes(imgs)
    if len(imgs) > 1:
        flow_dir = out / IMAGES_FLOW
        record["images"] = write_stream(imgs, world, (flow_dir, flow_dir / "flow_occ", flow_dir / "flow_noc"), "",
                                        codec)
    if sequence is not None:
        rel = Path("lidar") / "sequences" / sequence
        cams = stereo_images(root / rel)
        for stream in cams.values():
            check_passes(stream)
        for cam, stream in cams.items():
            if len(stream) > 1:
                record[f"image_{cam}"] = write_stream(stream, world, tuple(out / rel / f for f in STEREO_FLOW[cam]),
                                                      f"image_{cam}/", codec)
        if cams[2] and cams[3]:
            record["disparity"] = write_disparities(root / rel, codec, out / rel)
    log.info("motion ground truth: %s", record)
    return record


def motion_done(root: Path, plan, stereo_sweeps) -> bool:
    """Whether a town's flow files are all there (a resumed run with nothing new skips the step).

    ``plan``: the town's :class:`generator.jobs.plan.Plan`; ``stereo_sweeps``: its sweeps with a stereo pair.
    """
    root = Path(root)
    frames = list(plan.frames)
    if len(frames) > 1 and not all((root / IMAGES_FLOW / f"{k:06d}.exr").is_file() for k in frames):
        return False
    seq_dir = root / "lidar" / "sequences" / plan.sequence
    sweeps = list(stereo_sweeps)
    if len(sweeps) > 1 and not all((seq_dir / STEREO_FLOW[cam][0] / f"{j:06d}.exr").is_file()
                                   for cam in STEREO_FLOW for j in sweeps):
        return False
    return all((seq_dir / DISPARITY[0] / f"{j:06d}.exr").is_file() for j in sweeps)
