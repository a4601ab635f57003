"""Explicit, named random streams.

One integer seed comes from the spec. Every consumer asks for its own stream by
name (``stream(seed, "layout", "trees")``), so adding a feature that draws numbers
does not shift the draws of any other feature. No global seeding anywhere.

Naming convention: scene-wide draws start with what they build (``("layout", "trees")``,
``("assets", kind, i)``, ``("materials", name)``); per-frame draws start with the frame,
then the feature (``("frame", k, "camera")``, ``("frame", k, "lidar_intensity")``,
``("frame", k, "cycles", time_of_day, wet)``).
"""

from __future__ import annotations

import hashlib

import numpy as np


def _name_words(names: tuple[str | int, ...]) -> list[int]:
    digest = hashlib.sha256("/".join(str(n) for n in names).encode("utf-8")).digest()
    return [int.from_bytes(digest[i : i + 4], "little") for i in range(0, 16, 4)]


def stream(seed: int, *names: str | int) -> np.random.Generator:
    """Return the generator of the sub-stream ``names`` of ``seed``.

    Parameters
    ----------
    seed : int
        The spec's seed (any non-negative integer).
    *names : str or int
        Path of the sub-stream, e.g. ``("layout", "trees")`` or ``("frame", 12, "weather")``.

    Returns
    -------
    numpy.random.Generator
        A PCG64 generator; the same arguments always give the same stream.
    """
    if seed < 0:
        raise ValueError(f"seed must be >= 0, got {seed}")
    return np.random.Generator(np.random.PCG64(np.random.SeedSequence([int(seed), *_name_words(names)])))


def child_seed(seed: int, *names: str | int) -> int:
    """A 63-bit integer seed derived from ``seed`` and ``names`` (for other libraries)."""
    return int(stream(seed, *names).integers(0, 2**63 - 1))


def substream(g: np.random.Generator, *names: str | int) -> np.random.Generator:
    """A named sub-stream of the stream ``g`` was made from, without drawing from ``g``.

    An asset builder receives one generator (``stream(seed, "assets", kind, i)``); a feature added
    to it later draws from ``substream(g, "feature")`` so the builder's existing draws keep their
    values. Depends only on ``g``'s seed sequence (not on how far ``g`` has been drawn).

    Parameters
    ----------
    g : numpy.random.Generator
        A generator seeded from a ``SeedSequence`` (every generator of :func:`stream` and
        ``numpy.random.default_rng(int)``).
    *names : str or int
        Path of the sub-stream, e.g. ``("facade_detail",)``.
    """
    entropy = np.atleast_1d(np.asarray(g.bit_generator.seed_seq.entropy, dtype=object)).tolist()
    return np.random.Generator(np.random.PCG64(np.random.SeedSequence([*map(int, entropy), *_name_words(names)])))
