"""Synthetic-to-real domain-gap processing of seed 002 (§3.2, §4.1.2).

Three switchable parts, applied in this order after the intensity model and before the
LiDAR weather:

1. **random point removal**: exactly ``round(dropout * n)`` points, chosen uniformly
   without replacement, are removed (real sensors lose returns; a simulator never does);
2. **jitter**: each kept point moves by independent ``U(-jitter_m, +jitter_m)`` offsets
   along x, y and z of the sensor frame (real scans do not form perfect rings);
3. **constant intensity**: every remission becomes ``constant_intensity`` (the paper's
   answer to CARLA's unrealistic intensities).

The paper's preset (``seed002``) is 10 % removal, ±0.05 m, intensity "1". The paper writes
intensity on the sensor's 0-255 scale, where 1 is one of the most common values (poorly
reflecting road); SemanticKITTI's remission is on [0, 1], so the preset writes 1/255
(:data:`SEED002_INTENSITY`), not 1.0 (the maximum). The record says so (``scale_note``). A part is off
when its value is 0 / 0 / None. Randomness comes only from the generator passed in
(``stream(seed, "frame", k, "lidar_domain_gap")`` for frame ``k``).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from generator.errors import UserError


@dataclass(frozen=True)
class DomainGap:
    """Parameters of the processing.

    Attributes
    ----------
    dropout : float
        Fraction of points removed, in [0, 1).
    jitter_m : float
        Half-width of the uniform per-axis offset, metres (>= 0).
    constant_intensity : float or None
        Remission every point gets, in [0, 1]; None keeps the intensity model's values.
    """

    dropout: float = 0.0
    jitter_m: float = 0.0
    constant_intensity: float | None = None

    def __post_init__(self):
        if not 0.0 <= self.dropout < 1.0:
            raise UserError(f"domain gap: dropout must be in [0, 1), got {self.dropout}")
        if not 0.0 <= self.jitter_m <= 1.0:
            raise UserError(f"domain gap: jitter_m must be in [0, 1] m, got {self.jitter_m}")
        if self.constant_intensity is not None and not 0.0 <= self.constant_intensity <= 1.0:
            raise UserError(f"domain gap: constant_intensity must be in [0, 1] or null, got {self.constant_intensity}")

    def to_dict(self) -> dict:
        return asdict(self)


#: Named presets; ``seed002`` reproduces the paper.
#: Seed 002's constant intensity "1" on its 0-255 scale, written on SemanticKITTI's [0, 1] scale.
SEED002_INTENSITY = 1.0 / 255.0
SCALE_NOTE = ("remission is on SemanticKITTI's [0, 1] scale; seed 002's constant intensity 1 (of 0-255) "
              "is written as 1/255")

PRESETS: dict[str, DomainGap] = {
    "seed002": DomainGap(dropout=0.10, jitter_m=0.05, constant_intensity=SEED002_INTENSITY),
    "none": DomainGap(),
}


def preset(name: str) -> DomainGap:
    """A preset by name (``UserError`` listing the known ones)."""
    try:
        return PRESETS[name]
    except KeyError:
        raise UserError(f"unknown domain-gap preset {name!r}; known: {', '.join(PRESETS)}") from None


def gap_for_spec(spec) -> DomainGap | None:
    """The spec's ``lidar.domain_gap`` (None when ``enabled`` is false)."""
    g = spec.lidar.domain_gap
    return DomainGap(g.dropout, g.jitter_m, g.constant_intensity) if g.enabled else None


def apply_domain_gap(xyz: np.ndarray, remission: np.ndarray, gap: DomainGap,
                     rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray, dict]:
    """Remove, jitter and re-intensify one scan.

    Parameters
    ----------
    xyz : (n, 3) float32
        Sensor frame, metres.
    remission : (n,) float32
    gap : DomainGap
    rng : numpy.random.Generator

    Returns
    -------
    keep : (m,) int64
        Indices of the kept points in the input order (subset every other per-point array with it).
    xyz : (m, 3) float32
        Kept, jittered coordinates.
    remission : (m,) float32
    info : dict
        The parameters and the counts (``points_in``, ``removed``).
    """
    n = len(xyz)
    k = int(round(gap.dropout * n))
    if k:
        drop = np.zeros(n, bool)
        drop[rng.choice(n, size=k, replace=False)] = True
        keep = np.flatnonzero(~drop)
    else:
        keep = np.arange(n)
    out = np.asarray(xyz, np.float32)[keep]
    if gap.jitter_m > 0:
        out = (out + rng.uniform(-gap.jitter_m, gap.jitter_m, out.shape)).astype(np.float32)
    rem = np.asarray(remission, np.float32)[keep]
    if gap.constant_intensity is not None:
        rem = np.full(len(keep), gap.constant_intensity, np.float32)
    info = {**gap.to_dict(), "points_in": int(n), "removed": int(k)}
    if gap.constant_intensity is not None:
        info["scale_note"] = SCALE_NOTE
    return keep, out, rem, info


def apply_to_points(points: np.ndarray, remission: np.ndarray, gap: DomainGap,
                    rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, dict]:
    """:func:`apply_domain_gap` on a structured point array with ``x``, ``y``, ``z`` fields.

    The jitter moves x, y, z only; ``range`` (used by the LiDAR weather) keeps the cast value
    (the offsets are at most ``sqrt(3) * jitter_m``).
    """
    xyz = np.stack([points["x"], points["y"], points["z"]], -1)
    keep, xyz, rem, info = apply_domain_gap(xyz, remission, gap, rng)
    out = points[keep]
    out["x"], out["y"], out["z"] = xyz[:, 0], xyz[:, 1], xyz[:, 2]
    return out, rem, info
