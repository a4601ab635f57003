"""A model's image predictions found for the images of a sequence and projected onto its scans.

Two kinds of images carry a sequence's camera view (docs/dataset.md):

* the seed-003 images ``images/NNNNNN_<time>_<weather>`` of each frame, all weather x time variants sharing
  one camera, depth and label pass; a prediction is found by the Cityscapes stem the frame's export would
  have (:mod:`generator.formats.cityscapes_stems`), the way cityscapesScripts finds results; they are
  projected as ``fuse`` projects them (:func:`generator.fusion.agreement.fuse_frame`: de-skewed, the
  frame's exact camera, occlusion test on the rendered depth);
* the KITTI stream ``sequences/NN/image_2/NNNNNN.png``; a prediction is found by that file name. With the
  pair's record ``passes_2/NNNNNN.json`` (camera pose at the exposure, when the spinning LiDAR faces
  forward) the points are de-skewed to the exposure instant -- the sensor's motion and each moving actor's
  -- and projected with that pose, as frames are; without it (or with ``--no-deskew``) as KITTI tools do
  (:func:`generator.fusion.kitti_stream.project_scan`: raw points, ``P2 @ Tr``). The occlusion test uses
  ``passes_2``'s depth.

Each :class:`ViewLabels` holds, for the points of the scan inside one image, the predicted id at their
pixel (checked: a PNG of the image's size, single channel, ids of the label set), whether they pass the
occlusion test, whether their pixel lies on a 1-px class boundary of the *rendered* labels and the
rendered class there (the exclusions of the agreement report: :mod:`generator.fusion.agreement`).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from generator.errors import SpecError, UserError
from generator.formats import kitti_calib
from generator.formats.cityscapes_stems import image_stem_of
from generator.formats.label_png import check_ids, read_label_png
from generator.formats.prediction_files import PredictionFolder
from generator.fusion import projection as P
from generator.fusion.agreement import FusedFrame, fuse_frame
from generator.fusion.dataset import FusionDataset, deskewed, frame_variants
from generator.fusion.kitti_stream import project_scan
from generator.fusion.movers import deskew_movers
from generator.imaging import meta_fields as md
from generator.imaging.exr import read_exr
from generator.labels.class_sets import ClassSet

FRAME, STREAM = "frame", "image_2"


@dataclass(frozen=True)
class View:
    """One of our images with a model's prediction for it.

    Attributes
    ----------
    name : str
        The image's Cityscapes stem (kind ``frame``) or ``image_2`` file name.
    kind : {"frame", "image_2"}
    scan : int
        The scan (sweep) it was exposed with.
    prediction : Path
        The predicted label PNG.
    frame : int or None
        The image frame (kind ``frame``).
    """

    name: str
    kind: str
    scan: int
    prediction: Path
    frame: int | None = None


@dataclass
class ViewLabels:
    """A view's prediction at the scan points inside its image.

    Attributes
    ----------
    index : (m,) int64
        Rows of the scan's points inside the image.
    pred : (m,) int64
        Predicted id (of the label set) at each point's pixel.
    visible : (m,) bool
        The occlusion test.
    boundary : (m,) bool
        Pixel within 1 px of a rendered class boundary.
    image_class : (m,) uint8
        Rendered native class at the pixel.
    """

    index: np.ndarray
    pred: np.ndarray
    visible: np.ndarray
    boundary: np.ndarray
    image_class: np.ndarray


def find_views(ds: FusionDataset, folder: PredictionFolder, export_sequence: int) -> list[View]:
    """Every image of the sequence that has a prediction in ``folder``, in scan order."""
    views = []
    variants = frame_variants(ds.root) if ds.frames else {}
    for k in ds.frames:
        for meta in variants.get(k, []):
            stem = image_stem_of(meta.stem, export_sequence)
            hit = folder.by_stem(stem) if stem else None
            if hit is not None:
                views.append(View(stem, FRAME, ds.scan_of[k], hit, k))
    stream = ds.seq.dir / "image_2"
    scans = set(ds.seq.frames)
    for png in sorted(stream.glob("[0-9]*.png")) if stream.is_dir() else []:
        if png.stem.isdigit() and int(png.stem) in scans:
            hit = folder.by_name(png.name)
            if hit is not None:
                views.append(View(png.name, STREAM, int(png.stem), hit, None))
    return sorted(views, key=lambda v: (v.scan, v.kind, v.name))


def _prediction(view: View, shape: tuple[int, int], label_set: ClassSet) -> np.ndarray:
    pred = read_label_png(view.prediction, shape)
    check_ids(pred, label_set.known, view.prediction, label_set.name)
    return pred


class ViewProjector:
    """Projects views of one dataset sequence, caching what the weather variants of a frame share.

    Parameters
    ----------
    ds : FusionDataset
    label_set : ClassSet
        What the predicted pixel values are.
    deskew : bool
    abs_tol_m, rel_tol : float
        Occlusion-test tolerances (:func:`generator.fusion.projection.visible`).
    actors : dict or None
        Moving actors' poses for de-skewing them (:func:`generator.fusion.movers.actor_poses`).
    """

    def __init__(self, ds: FusionDataset, label_set: ClassSet, deskew: bool, abs_tol_m: float, rel_tol: float,
                 actors=None):
        self.ds, self.label_set = ds, label_set
        self.deskew, self.abs_tol_m, self.rel_tol, self.actors = deskew, abs_tol_m, rel_tol, actors
        self._frame: tuple[int, FusedFrame, tuple[int, int]] | None = None
        self._calib = None

    def project(self, view: View) -> ViewLabels:
        """The prediction of ``view`` at the scan's points (reads and checks the PNG)."""
        if view.kind == FRAME:
            if self._frame is None or self._frame[0] != view.frame:
                frame = self.ds.read(view.frame)
                fused = fuse_frame(frame, self.deskew, self.abs_tol_m, self.rel_tol, self.actors)
                self._frame = (view.frame, fused, frame.class_id.shape)
            _, fused, shape = self._frame
            pred = _prediction(view, shape, self.label_set)
            proj = fused.proj
            return ViewLabels(proj.index, pred[proj.row, proj.col], fused.visible, fused.boundary, fused.image_class)
        meta = self.ds.seq.dir / "passes_2" / f"{view.scan:06d}.json"
        if self.deskew and os.path.lexists(meta):
            return self._stream_exact(view, meta)
        if self._calib is None:
            self._calib = kitti_calib.read_calib(self.ds.seq.dir / "calib.txt")
        sv = project_scan(self.ds.seq.dir, view.scan, self._calib)
        pred = _prediction(view, sv.shape, self.label_set)
        return ViewLabels(sv.proj.index, pred[sv.proj.row, sv.proj.col], sv.visible, sv.boundary, sv.image_class)

    def _stream_exact(self, view: View, meta_path: Path) -> ViewLabels:
        """An ``image_2`` view with its recorded pose: points de-skewed to its exposure, as ``fuse`` projects frames."""
        src = str(meta_path)
        meta = md.load_metadata(meta_path)
        T_world_camera = md.matrix(meta, "T_world_camera", (4, 4), src)
        K = md.matrix(meta, "K", (3, 3), src)
        offset = md.field(meta, "exposure_offset_s", src)
        if isinstance(offset, bool) or not isinstance(offset, (int, float)) or not 0 <= offset <= 1:
            raise SpecError(src, "exposure_offset_s", "must be a number of seconds in [0, 1]")
        scan = self.ds.read_scan(view.scan)
        xyz = deskewed(scan, True, None)
        if self.actors:
            if scan["t_sweep"] is None:
                raise UserError(f"{self.ds.seq.dir / 'times.txt'}: needed to de-skew the moving actors")
            xyz = deskew_movers(xyz, scan["instance"], scan["times"], scan["t_sweep"], scan["t_sweep"] + offset,
                                scan["T_world_lidar_start"], self.actors)
        img = read_exr(meta_path.with_suffix(".exr"))
        h, w = img.class_id.shape
        proj = P.project(P.transform(P.camera_from_lidar(T_world_camera, scan["T_world_lidar_start"]), xyz), K, w, h)
        vis = P.visible(proj, img.depth, K, self.abs_tol_m, self.rel_tol)
        pred = _prediction(view, (h, w), self.label_set)
        return ViewLabels(proj.index, pred[proj.row, proj.col], vis, P.boundary_mask(img.class_id)[proj.row, proj.col],
                          img.class_id[proj.row, proj.col])
