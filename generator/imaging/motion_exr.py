"""Float motion maps of an image as an EXR: optical flow (forward and backward) or stereo disparity.

One scanline EXR per image (ZIP), beside the KITTI PNGs, for training code that wants the
exact floats and every mask (:mod:`generator.motion`):

======================  ======  ==============================================================
channel                 type    content
======================  ======  ==============================================================
``forward.U`` ``.V``    FLOAT   flow to the stream's next image, pixels (u right, v down); 0 where
                                not known
``forward.flags``       UINT    bit 1 known (KITTI ``flow_occ``), 2 visible there (``flow_noc``),
                                4 on an actor (the rest moves with the ego alone)
``backward.*``          ...     the same to the stream's previous image
``disparity.D``         FLOAT   ``f b / Z`` in pixels (left image of a stereo pair); 0 where none
``disparity.flags``     UINT    bit 1 known (``disp_occ``), 2 visible in the right image (``disp_noc``)
======================  ======  ==============================================================

A flow file holds ``forward`` and/or ``backward`` (the first image of a stream has no
backward flow, the last no forward one); a disparity file holds ``disparity``. Header
attributes: ``urbangen.motion`` (``flow`` or ``disparity``), ``urbangen.image`` (the image the
map belongs to), ``urbangen.forward`` / ``urbangen.backward`` (the images the flows lead to),
``urbangen.definition`` and ``urbangen.version``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import OpenEXR

from generator import __version__
from generator.atomic import atomic_path
from generator.errors import UserError
from generator.imaging.exr import CODECS, channel_names, read_channels
from generator.safeload import printable

DIRECTIONS = ("forward", "backward")
FLOW_DEFINITION = ("flow of each pixel centre's surface point, carried by its object's rigid motion and "
                   "projected with the other image's camera, minus the pixel centre; pixels, u right, v down")
DISPARITY_DEFINITION = "f_x * baseline / Z of each left pixel centre's surface point, pixels (KITTI stereo 2015)"


KNOWN, VISIBLE, ACTOR = 1, 2, 4


@dataclass
class FlowMaps:
    """The flows of one image, as training code reads them.

    Attributes
    ----------
    forward, backward : (H, W, 2) float32 or None
        Flow to the stream's next / previous image, pixels (u right, v down); None at a stream's
        end / start.
    forward_flags, backward_flags : (H, W) uint8 or None
        Bits :data:`KNOWN` (KITTI ``flow_occ``), :data:`VISIBLE` (``flow_noc``), :data:`ACTOR`.
    to : dict
        ``"forward"`` / ``"backward"`` -> the image each flow leads to.
    """

    forward: np.ndarray | None = None
    forward_flags: np.ndarray | None = None
    backward: np.ndarray | None = None
    backward_flags: np.ndarray | None = None
    to: dict = field(default_factory=dict)

    def valid(self, direction: str = "forward", visible: bool = False) -> np.ndarray:
        """(H, W) bool: pixels whose flow is known (``visible``: and seen in the other image)."""
        flags = getattr(self, f"{direction}_flags")
        if flags is None:
            raise ValueError(f"this image has no {direction} flow (the end of its stream)")
        return (flags & (VISIBLE if visible else KNOWN)) > 0


@dataclass
class DisparityMap:
    """Disparity of a stereo pair's left image: ``d`` (H, W) float32 pixels and ``flags`` (H, W) uint8
    (:data:`KNOWN` = KITTI ``disp_occ``, :data:`VISIBLE` = ``disp_noc``)."""

    d: np.ndarray
    flags: np.ndarray

    def valid(self, visible: bool = False) -> np.ndarray:
        return (self.flags & (VISIBLE if visible else KNOWN)) > 0


def write_flow_exr(path: str | Path, image: str, flows: dict, to: dict[str, str], codec: str = "zip") -> None:
    """Write the flows of one image.

    Parameters
    ----------
    image : str
        The image they belong to (``000003`` of ``images/``, ``image_2/000010``).
    flows : dict
        ``"forward"`` and/or ``"backward"`` -> :class:`generator.motion.optical_flow.Flow`.
    to : dict
        The same keys -> the image each flow leads to.
    """
    channels = {}
    for d, f in flows.items():
        if d not in DIRECTIONS:
            raise ValueError(f"flow direction {d!r}")
        channels[f"{d}.U"] = np.ascontiguousarray(f.uv[..., 0], np.float32)
        channels[f"{d}.V"] = np.ascontiguousarray(f.uv[..., 1], np.float32)
        channels[f"{d}.flags"] = np.ascontiguousarray(f.flags, np.uint32)
    header = {"urbangen.motion": "flow", "urbangen.image": image, "urbangen.definition": FLOW_DEFINITION,
              **{f"urbangen.{d}": to[d] for d in flows}}
    _write(path, channels, header, codec)


def write_disparity_exr(path: str | Path, image: str, d: np.ndarray, flags: np.ndarray, codec: str = "zip") -> None:
    """Write the disparity map (H, W) float32 and its flags (H, W) of the left image ``image``."""
    _write(path, {"disparity.D": np.ascontiguousarray(d, np.float32),
                  "disparity.flags": np.ascontiguousarray(flags, np.uint32)},
           {"urbangen.motion": "disparity", "urbangen.image": image, "urbangen.definition": DISPARITY_DEFINITION},
           codec)


def _write(path, channels: dict, header: dict, codec: str) -> None:
    header = {"compression": CODECS[codec], "type": OpenEXR.scanlineimage, "urbangen.version": __version__, **header}
    with atomic_path(path, suffix=".exr") as tmp:
        with OpenEXR.File(header, channels) as f:
            f.write(str(tmp))


def read_flow_exr(path: str | Path) -> FlowMaps:
    """The :class:`FlowMaps` of a flow EXR."""
    present = set(channel_names(path))
    dirs = [d for d in DIRECTIONS if f"{d}.U" in present]
    if not dirs:
        raise UserError(f"{printable(path)}: no forward.U or backward.U channel: not a urbangen flow file")
    names = [f"{d}.{c}" for d in dirs for c in ("U", "V", "flags")]
    ch, header = read_channels(path, names)
    out = FlowMaps()
    for d in dirs:
        setattr(out, d, np.stack([ch[f"{d}.U"], ch[f"{d}.V"]], -1).astype(np.float32))
        setattr(out, f"{d}_flags", _flags(ch[f"{d}.flags"], path))
        out.to[d] = str(header.get(f"urbangen.{d}", ""))
    return out


def read_disparity_exr(path: str | Path) -> DisparityMap:
    """The :class:`DisparityMap` of a disparity EXR."""
    ch, _ = read_channels(path, ["disparity.D", "disparity.flags"])
    return DisparityMap(ch["disparity.D"].astype(np.float32), _flags(ch["disparity.flags"], path))


def _flags(values: np.ndarray, path) -> np.ndarray:
    if values.dtype.kind not in "iu" or (values.size and int(values.max()) > 7):
        raise UserError(f"{printable(path)}: flag channels must be UINT with values 0..7")
    return values.astype(np.uint8)
