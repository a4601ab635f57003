"""Track pieces trams run on, straight along x.

``rail_track`` is a ballast bed with sleepers and two rails (class ``rail_track``: Cityscapes
"rail track" 10, SemanticKITTI other-ground 49); its anchor ``"rail_top"`` marks where a tram's
z = 0 goes. ``tram_rails`` are grooved rails laid flush in a street: class ``road``, since
Cityscapes counts tram tracks drivable by cars as road (and SemanticKITTI has no rail class).
Origin at the centre of the footprint, bottom at z = 0.
"""

from __future__ import annotations

import numpy as np

from generator.geometry import Mesh, box, merge, pose, prism

GAUGE = 1.435         # standard gauge, between the inner faces of the rail heads

#: rail cross-section (y, z), counter-clockwise seen from +x: foot, web and head of a ~60 kg rail
RAIL_PROFILE = np.array([[-0.075, 0.0], [0.075, 0.0], [0.075, 0.012], [0.009, 0.03], [0.009, 0.115], [0.036, 0.125],
                         [0.036, 0.16], [-0.036, 0.16], [-0.036, 0.125], [-0.009, 0.115], [-0.009, 0.03],
                         [-0.075, 0.012]])
#: prism coordinates (px, py, pz) -> (x, y, z) = (pz, px, py): extrude a (y, z) profile along x
_ALONG_X = np.array([[0.0, 0.0, 1.0, 0.0], [1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]])


def _along_x(profile: np.ndarray, x0: float, x1: float, cls: str, material: str, top_material: str | None = None,
             y: float = 0.0, z: float = 0.0) -> Mesh:
    m = prism(profile, x0, x1, cls, material, top_material=top_material, bottom=True).transformed(_ALONG_X)
    return m.transformed(pose(0.0, y, z))


def rail_track(rng: np.random.Generator, length: float = 10.0, sleeper: str | None = None) -> Mesh:
    """A straight piece of ballasted track along x: ballast bed, sleepers every ~0.6 m, two rails.

    Parameters
    ----------
    length : float
        Metres (>= 1.2); pieces tile end to end.
    sleeper : {"concrete", "wood"}, optional
        Sleeper material; drawn when omitted.

    Returns
    -------
    Mesh
        Class ``rail_track``; bed 3.0-3.4 m wide at the bottom; anchor ``"rail_top"`` (2, 3) at
        the track centre line on the rail tops at both ends (where a tram's z = 0 goes).
    """
    if length < 1.2:
        raise ValueError(f"rail_track length must be >= 1.2 m, got {length}")
    sleeper = str(rng.choice(["concrete", "wood"])) if sleeper is None else sleeper
    if sleeper not in ("concrete", "wood"):
        raise ValueError(f"rail_track sleeper must be 'concrete' or 'wood', got {sleeper!r}")
    cls = "rail_track"
    bottom_w, top_w, bed_h = float(rng.uniform(3.0, 3.4)), float(rng.uniform(2.5, 2.7)), float(rng.uniform(0.25, 0.35))
    L = float(length)
    bed = np.array([[-bottom_w / 2, 0.0], [bottom_w / 2, 0.0], [top_w / 2, bed_h], [-top_w / 2, bed_h]])
    parts = [_along_x(bed, -L / 2, L / 2, cls, "curb_concrete")]
    sl_mat, sl_h = ("facade_concrete", 0.2) if sleeper == "concrete" else ("fence_wood", 0.15)
    pitch = 0.6
    k = max(1, int(round(L / pitch)))
    for x in -L / 2 + (np.arange(k) + 0.5) * L / k:
        parts.append(box((0.26, 2.6, sl_h), cls, sl_mat, (x, 0.0, bed_h - 0.06 + sl_h / 2), bottom=False))
    z_rail = bed_h - 0.06 + sl_h
    for s in (1.0, -1.0):
        yc = s * (GAUGE / 2 + 0.036)
        parts.append(_along_x(RAIL_PROFILE, -L / 2, L / 2, cls, "pole_metal", top_material=None, y=yc, z=z_rail))
        # polished running surface on the head
        parts.append(box((L, 0.05, 0.004), cls, "chrome", (0.0, yc, z_rail + 0.162), bottom=False))
    out = merge(parts)
    rail_top = z_rail + 0.164
    out.anchors = {"rail_top": np.array([[-L / 2, 0.0, rail_top], [L / 2, 0.0, rail_top]])}
    return out


def tram_rails(rng: np.random.Generator, length: float = 10.0) -> Mesh:
    """Grooved tram rails laid flush in a street, along x: two steel heads with their grooves.

    Class ``road`` (Cityscapes counts tram tracks drivable by cars as road; SemanticKITTI has no
    rail class). 6 mm proud of z = 0 so they win the depth test against the road surface they
    lie on; anchor ``"rail_top"`` (2, 3) as for :func:`rail_track`.
    """
    if length < 0.5:
        raise ValueError(f"tram_rails length must be >= 0.5 m, got {length}")
    L = float(length)
    wear = float(rng.uniform(0.0, 0.002))
    parts = []
    for s in (1.0, -1.0):
        yc = s * (GAUGE / 2 + 0.03)
        parts.append(box((L, 0.06, 0.006 - wear), "road", "chrome", (0.0, yc, (0.006 - wear) / 2), bottom=False))
        parts.append(box((L, 0.04, 0.004), "road", "rubber", (0.0, yc - s * 0.05, 0.002), bottom=False))
        parts.append(box((L, 0.02, 0.006), "road", "pole_metal", (0.0, yc - s * 0.08, 0.003), bottom=False))
    out = merge(parts)
    out.anchors = {"rail_top": np.array([[-L / 2, 0.0, 0.006], [L / 2, 0.0, 0.006]])}
    return out
