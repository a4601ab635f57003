"""Leaves as geometry: sprays of leaf-shaped triangles instanced (in numpy) on leaf clusters.

Foliage is made of real leaf triangles, not alpha cut-outs, so the LiDAR casts against the very
leaves the camera sees. Triangles are few on purpose (a street tree carries a few hundred
sprays, a town thousands of trees): a *spray* is a twig end with a small fan of ``k`` leaves,
each leaf one triangle with its own three vertices, so the shaders' "Random Per Island" shades
leaf by leaf. Sprays sit on the outer shell of a cluster whose dark, low-poly core keeps the
crown from looking hollow (:mod:`assets_procedural.vegetation`, :mod:`assets_procedural.shrubs`).

Leaf frame: the petiole end at the spray centre, the blade along the leaf axis ``x`` (length
1), its half-width along ``y``; the upper side faces the spray's ``up``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from generator.geometry import Mesh, cross, icosphere, unit
from generator.geometry.primitives import resolve_ids


@dataclass(frozen=True)
class Leaf:
    """The look of one species' sprays (lengths in metres; ranges drawn uniformly per spray)."""

    length: tuple[float, float]   #: leaf length
    width: float                  #: half-width of the leaf's base / its length
    base: float                   #: where along the blade the widest part is (0: at the twig, heart-shaped)
    per_spray: int                #: leaves (triangles) per spray
    fan: float                    #: opening angle of a spray's fan, degrees
    droop: float = 0.2            #: how far leaf tips hang, in leaf lengths


#: Leaf looks by name: broad palmate plane leaves, heart-shaped linden, small narrow birch leaves,
#: an ordinary ovate leaf (young trees, bushes), small dense box-like hedge leaves and needle sprays.
LEAVES: dict[str, Leaf] = {
    "broad": Leaf((0.3, 0.4), 0.5, 0.3, 5, 200.0, 0.15),
    "heart": Leaf((0.2, 0.26), 0.5, 0.12, 5, 220.0, 0.2),
    "narrow": Leaf((0.14, 0.2), 0.26, 0.4, 4, 120.0, 0.55),
    "ovate": Leaf((0.18, 0.24), 0.34, 0.35, 5, 200.0, 0.2),
    "small": Leaf((0.1, 0.14), 0.38, 0.3, 4, 240.0, 0.1),
    "needle": Leaf((0.4, 0.55), 0.08, 0.1, 6, 150.0, 0.3),
}


def sprays(rng: np.random.Generator, centre: np.ndarray, outward: np.ndarray, leaf: Leaf, cls: str,
           material: str, scale: float = 1.0) -> Mesh:
    """Sprays of leaves, all at once.

    Parameters
    ----------
    rng : numpy.random.Generator
    centre : (n, 3) float
        Twig ends (spray centres), metres.
    outward : (n, 3) float
        Where each spray points (the fan opens around it); need not be unit.
    leaf : Leaf
    cls, material : str
        Class and material of every leaf.
    scale : float
        Multiplies the leaf length (small trees, bushes).

    Returns
    -------
    Mesh
        ``n * leaf.per_spray`` triangles, each its own island of three vertices, counter-clockwise
        seen from the leaf's upper side.
    """
    centre = np.asarray(centre, np.float64).reshape(-1, 3)
    n, k = len(centre), leaf.per_spray
    d = unit(np.asarray(outward, np.float64).reshape(-1, 3) + 0.35 * rng.normal(size=(n, 3)))
    up = unit(np.array([0.0, 0.0, 1.0]) + 0.6 * d + 0.5 * rng.normal(size=(n, 3)))
    side = cross(up, d)
    side = np.where(np.linalg.norm(side, axis=1, keepdims=True) < 1e-6, [1.0, 0.0, 0.0], side)
    side = unit(side)
    up = cross(d, side)
    fan = np.radians(leaf.fan)
    theta = np.linspace(-fan / 2, fan / 2, k)[None] + rng.uniform(-0.35, 0.35, (n, k))   # (n, k)
    length = rng.uniform(*leaf.length, (n, k)) * scale
    c, s = np.cos(theta)[..., None], np.sin(theta)[..., None]
    x = c * d[:, None] + s * side[:, None]                  # (n, k, 3) leaf axes
    y = c * side[:, None] - s * d[:, None]                  # across the blade, near the spray plane
    y = unit(y + 0.45 * rng.normal(size=(n, k, 3)))        # each blade rolled its own way: no flat star
    y = unit(y - (y * x).sum(-1, keepdims=True) * x)
    y = np.where((cross(x, y) * up[:, None]).sum(-1, keepdims=True) < 0, -y, y)   # upper side toward ``up``
    z = cross(x, y)
    lw = (leaf.width * length)[..., None]
    lb = (leaf.base * length)[..., None]
    tip = x * length[..., None] - z * (leaf.droop * length)[..., None]
    # leaves stand along the twig (0-0.2 leaf lengths out), not all from one point
    base = centre[:, None] + (0.15 * x + 0.2 * rng.random((n, k, 1)) * d[:, None]) * length[..., None]
    v = np.stack([base + lb * x - lw * y, base + tip, base + lb * x + lw * y], 2)   # (n, k, 3, 3)
    m = n * k
    cid, mid = resolve_ids(cls, material)
    return Mesh(v.reshape(-1, 3), np.arange(3 * m, dtype=np.int64).reshape(m, 3), cid, mid)


def shell(rng: np.random.Generator, centres: np.ndarray, radii: np.ndarray, counts: np.ndarray,
          inner: float = 0.85, outer: float = 1.15, lift: float = 0.3) -> tuple[np.ndarray, np.ndarray]:
    """Points on the outer shell of ellipsoidal clusters, with the outward direction at each.

    Parameters
    ----------
    centres, radii : (c, 3) float
        Cluster centres and half-axes, metres.
    counts : (c,) int
        Points per cluster.
    inner, outer : float
        Radial range of the points, fractions of the ellipsoid.
    lift : float
        Bias of the directions toward the sky (leaves crowd where the light is).

    Returns
    -------
    points, outward : (counts.sum(), 3) float
        ``outward`` is unit.
    """
    owner = np.repeat(np.arange(len(centres)), counts)
    d = unit(rng.normal(size=(len(owner), 3)) + [0.0, 0.0, lift])
    r = rng.uniform(inner, outer, len(owner))
    local = d * r[:, None] * radii[owner]
    return centres[owner] + local, unit(local / np.maximum(radii[owner], 1e-9) ** 2)


def cores(rng: np.random.Generator, centres: np.ndarray, radii: np.ndarray, cls: str, material: str,
          jitter: float = 0.15) -> Mesh:
    """Low-poly (20-triangle) jittered ellipsoids, the shaded inner body of leaf clusters.

    Parameters
    ----------
    centres, radii : (c, 3) float
        Metres.

    Returns
    -------
    Mesh
        ``20 * c`` triangles.
    """
    ico = icosphere(1.0, cls, material, 0)
    c, k = len(centres), len(ico.vertices)
    r = 1.0 + rng.uniform(-jitter, jitter, (c, k))
    v = ico.vertices[None] * r[..., None] * np.asarray(radii)[:, None] + np.asarray(centres)[:, None]
    faces = (ico.faces[None] + k * np.arange(c)[:, None, None]).reshape(-1, 3)
    return Mesh(v.reshape(-1, 3), faces, np.tile(ico.face_class, c), np.tile(ico.face_material, c))
