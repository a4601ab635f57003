"""A field of view that ``gap`` compares within: cropped scans such as KITTI's ``velodyne_reduced``.

KITTI's object benchmark ships scans cut to the left camera's image (``velodyne_reduced``: about ±40° of
azimuth, nothing below about -14.5° of elevation), and a model's predictions often exist only where a camera
looked. Against such a scan, every ray outside the crop would count as lost. A :class:`Window` names the
azimuth and elevation range (degrees, sensor frame: x forward, azimuth anticlockwise seen from above, so
+y = left is +90°; elevation up positive) in which points and rays are compared; a ray of ring ``r`` and
firing column ``c`` is inside when its laser's elevation and its direction at that column (the column's
encoder angle plus the laser's azimuth offset) are inside, and a point is kept when the cell the ring fit
gives it is inside. So a dataset's rays lost per ring stay a share of the rays fired into the window.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from generator.errors import UserError


@dataclass(frozen=True)
class Window:
    """Azimuth ``[az_lo, az_hi]`` and elevation ``[el_lo, el_hi]``, degrees (see the module docstring)."""

    az_lo: float = -180.0
    az_hi: float = 180.0
    el_lo: float = -90.0
    el_hi: float = 90.0

    @property
    def whole(self) -> bool:
        """The window holds every direction."""
        return self.az_hi - self.az_lo >= 360.0 and self.el_lo <= -90.0 and self.el_hi >= 90.0

    def to_dict(self) -> dict:
        return {"azimuth_deg": [self.az_lo, self.az_hi], "elevation_deg": [self.el_lo, self.el_hi]}

    def cells(self, model) -> np.ndarray:
        """(rings, steps) bool: the rays of a :class:`generator.gap.rings.RingModel` inside the window.

        Rows are rings (0 = highest beam, as :class:`~generator.gap.rings.RingFit` numbers them), columns
        the firing columns of the sensor's azimuth grid.
        """
        n = len(model.elev)
        elev = np.empty(n)
        rot = np.empty(n)
        elev[model.ring_of], rot[model.ring_of] = model.elev, model.rot
        s = model.sensor
        sign = -1.0 if s.clockwise else 1.0
        psi = s.start_azimuth_rad + sign * np.arange(model.steps) * (2.0 * math.pi / model.steps)
        az = np.degrees(psi[None, :] + rot[:, None])
        inside_az = np.mod(az - self.az_lo, 360.0) <= (self.az_hi - self.az_lo)
        el = np.degrees(elev)
        return inside_az & ((el >= self.el_lo) & (el <= self.el_hi))[:, None]


def _range(text: str, option: str, lo: float, hi: float) -> tuple[float, float]:
    parts = text.split(":")
    try:
        a, b = (float(p) for p in parts) if len(parts) == 2 else (None, None)
    except ValueError:
        a = b = None
    if a is None or not (math.isfinite(a) and math.isfinite(b)):
        raise UserError(f"{option}: {text!r} is not LO:HI in degrees (e.g. {option}={lo:g}:{hi:g})")
    if not lo <= a < b <= hi:
        raise UserError(f"{option}: {text!r} must satisfy {lo:g} <= LO < HI <= {hi:g} degrees")
    return a, b


def parse_window(azimuth: str | None, elevation: str | None) -> Window:
    """The window of the ``--azimuth`` and ``--elevation`` options (``LO:HI`` degrees; None: all).

    Raises
    ------
    UserError
        A value that is not two numbers ``LO < HI`` in range, naming the option.
    """
    az = _range(azimuth, "--azimuth", -180.0, 180.0) if azimuth is not None else (-180.0, 180.0)
    el = _range(elevation, "--elevation", -90.0, 90.0) if elevation is not None else (-90.0, 90.0)
    return Window(az[0], az[1], el[0], el[1])
