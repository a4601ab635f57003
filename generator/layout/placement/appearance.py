"""How vehicles and people look: fleet paint and clothing colours, drawn per object.

The distributions are data (``appearance.yaml``, next to this module). Prototypes are shared
by many objects (six car meshes serve a whole town), so colours are per object: the layout
draws them with the functions here and stores them in the object's ``attrs`` (linear RGB in
[0, 1]); the Blender edge hands ``attrs["color"]`` to ``Object.color`` and every other
``attrs["<name>_color"]`` to the object property ``ug_<name>_color`` that the material recipes
read (``car_paint``, ``clothing``, ``clothing_bottom``, ``shoes``, ``skin``, ``hair``).

Each draw takes a fixed number of values from its generator (4 per colour), so changing a
distribution changes colours only, never where anything stands.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from generator.materials import srgb_to_linear
from generator.safeload import load_package_yaml

DRAWS_PER_COLOUR = 4  #: values one colour takes from its generator: the pick and 3 channel jitters


@dataclass(frozen=True)
class Palette:
    """A discrete colour distribution.

    Attributes
    ----------
    names : tuple of str
    p : (n,) float64
        Probabilities (sum 1).
    srgb : (n, 3) uint8
        The entries as written in ``appearance.yaml``.
    linear : (n, 3) float64
        The entries in linear RGB, [0, 1].
    cdf : (n,) float64
        Cumulative ``p``.
    """

    names: tuple[str, ...]
    p: np.ndarray
    srgb: np.ndarray
    linear: np.ndarray
    cdf: np.ndarray  # cumulative p, for the inverse-CDF draw

    @classmethod
    def from_rows(cls, rows: list, where: str) -> Palette:
        if not rows:
            raise ValueError(f"appearance.yaml: {where} is empty")
        names, shares, colours = [], [], []
        for row in rows:
            if len(row) != 3 or len(row[2]) != 3:
                raise ValueError(f"appearance.yaml: {where}: each entry is [name, share, [r, g, b]], got {row!r}")
            name, share, rgb = row
            if not float(share) > 0 or not all(0 <= int(v) <= 255 for v in rgb):
                raise ValueError(f"appearance.yaml: {where}: {name}: share must be > 0 and r, g, b in 0..255")
            names.append(str(name))
            shares.append(float(share))
            colours.append([int(v) for v in rgb])
        if len(set(names)) != len(names):
            raise ValueError(f"appearance.yaml: {where}: duplicate names")
        p = np.array(shares) / np.sum(shares)
        srgb = np.array(colours, np.uint8)
        return cls(tuple(names), p, srgb, srgb_to_linear(srgb), np.cumsum(p))

    def index(self, u: float) -> int:
        """The entry a uniform number ``u`` in [0, 1) picks (inverse CDF)."""
        return int(min(np.searchsorted(self.cdf, u, side="right"), len(self.p) - 1))

    def draw(self, rng: np.random.Generator, jitter: float = 0.0) -> tuple[str, list[float]]:
        """(name, linear RGB as 3 floats rounded to 1e-4) of one draw; takes 4 values from ``rng``.

        ``jitter`` spreads each channel by a factor uniform in [1 - jitter, 1 + jitter].
        """
        u = rng.random(DRAWS_PER_COLOUR)
        k = self.index(float(u[0]))
        rgb = np.clip(self.linear[k] * (1.0 + jitter * (2.0 * u[1:] - 1.0)), 0.0, 1.0)
        return self.names[k], [round(float(v), 4) for v in rgb]


@dataclass(frozen=True)
class Appearance:
    """Every distribution of ``appearance.yaml``."""

    fleet: Palette
    fleet_jitter: float
    metallic: frozenset[str]
    top: Palette
    bottom: Palette
    shoes: Palette
    skin: Palette
    hair: Palette


@functools.cache
def appearance() -> Appearance:
    """The package's appearance table (read once)."""
    with open(Path(__file__).with_name("appearance.yaml"), encoding="utf-8") as f:
        raw = load_package_yaml(f)
    fleet = Palette.from_rows(raw["fleet"]["paints"], "fleet.paints")
    metallic = frozenset(raw["fleet"].get("metallic", []))
    if not metallic <= set(fleet.names):
        raise ValueError(f"appearance.yaml: fleet.metallic names unknown paints: {sorted(metallic - set(fleet.names))}")
    c = raw["clothing"]
    return Appearance(fleet, float(raw["fleet"]["jitter"]), metallic,
                      Palette.from_rows(c["top"], "clothing.top"), Palette.from_rows(c["bottom"], "clothing.bottom"),
                      Palette.from_rows(c["shoes"], "clothing.shoes"), Palette.from_rows(raw["skin"], "skin"),
                      Palette.from_rows(raw["hair"], "hair"))


def fleet_paint(rng: np.random.Generator) -> dict:
    """A vehicle's paint from the fleet distribution, as object attributes.

    Returns
    -------
    dict
        ``color`` (linear RGB, 3 floats), ``paint`` (its name in ``appearance.yaml``) and
        ``paint_metallic`` (1.0 for metallic paints, else 0.0). Takes 4 values from ``rng``.
    """
    a = appearance()
    name, rgb = a.fleet.draw(rng, a.fleet_jitter)
    return {"color": rgb, "paint": name, "paint_metallic": 1.0 if name in a.metallic else 0.0}


def outfit(rng: np.random.Generator) -> dict:
    """A person's colours: top, bottom, shoes, skin and hair, as object attributes.

    Returns
    -------
    dict
        ``color`` (the top: ``Object.color``), ``bottom_color``, ``shoe_color``, ``skin_color``,
        ``hair_color`` (linear RGB, 3 floats each) and ``outfit`` (the names drawn, in that
        order). Takes 20 values from ``rng``.
    """
    a = appearance()
    names, out = [], {}
    for key, pal, jit in (("color", a.top, 0.08), ("bottom_color", a.bottom, 0.08), ("shoe_color", a.shoes, 0.05),
                          ("skin_color", a.skin, 0.06), ("hair_color", a.hair, 0.1)):
        name, rgb = pal.draw(rng, jit)
        names.append(name)
        out[key] = rgb
    out["outfit"] = "/".join(names)
    return out
