"""Many towns from one spec: ``town.redraw_every_frames`` (a new town every N image frames).

With the option off (null, the default) a ``generate`` run shows one town, drawn from the
spec's ``seed``, exactly as before. With ``N`` set, image frame ``k`` belongs to town
``i = k // N``; town ``i`` is the spec with

* ``seed`` = :func:`town_seed` (``child_seed(seed, "town", i)``, 53 bits): its street grid, lots,
  placements, traffic, camera jitter, weather and lighting draws are its own;
* ``asset_seed`` = the spec's seed, from which :func:`library_seed` draws the seed of the town's
  asset library (the prototype meshes of cars, people, trucks, trees ...): with
  ``assets.redraw_every_towns`` = M (default 1) towns ``j*M .. j*M+M-1`` share library ``j``, drawn
  from the stream ``("assets", "library", j)``; with it null every town shares the spec seed's
  library (as before issue 29). Towns that share a library reuse its meshes through the prototype cache;
* ``town_index`` = ``i`` (recorded in image metadata and ``lidar_meta.json`` as ``town``);
* the same ``spec_hash`` (it names the spec file, not the town).

Frame ``k`` is driven ``(k - i*N) * paths.spacing_m`` metres along town ``i``'s route: every
town's drive starts at its own t = 0 and is its own LiDAR sequence.
"""

from __future__ import annotations

import dataclasses

from generator.errors import UserError
from generator.rng import child_seed, stream


def redraw_every(spec) -> int | None:
    """Image frames per town, or None when the run shows one town."""
    n = spec.town.redraw_every_frames
    return None if n is None else int(n)


def town_seed(seed: int, index: int) -> int:
    """The seed of town ``index`` of a spec whose seed is ``seed``: from the stream ``("town", index)``,
    kept below 2**53 so that every JSON reader (JavaScript's numbers too) reads it exactly."""
    return child_seed(int(seed), "town", int(index)) >> 10


def town_of(spec, frame: int) -> int | None:
    """The town image frame ``frame`` belongs to (None when the spec re-draws nothing)."""
    n = redraw_every(spec)
    return None if n is None else int(frame) // n


def first_frame(spec, index: int | None) -> int:
    """The frame number at the start of town ``index``'s drive (0 for the one town)."""
    return 0 if index is None else int(index) * redraw_every(spec)


def frames_by_town(spec, frames) -> dict[int, list[int]]:
    """Image frames grouped by the town that shows them: ``{town index: sorted frames}`` (a spec that
    re-draws no town must not be asked: every frame is then of the one town)."""
    groups: dict[int, list[int]] = {}
    for k in sorted(frames):
        groups.setdefault(town_of(spec, k), []).append(k)
    return dict(sorted(groups.items()))


def town_spec(spec, index: int | None):
    """The spec of town ``index`` (see the module docstring); ``spec`` itself for None.

    Raises
    ------
    ValueError
        If ``spec`` is already a town's spec, or the spec re-draws no town.
    """
    if index is None:
        return spec
    if spec.town_index is not None:
        raise ValueError(f"{spec.source}: already the spec of town {spec.town_index}")
    if redraw_every(spec) is None:
        raise ValueError(f"{spec.source}: town.redraw_every_frames is null (one town)")
    return dataclasses.replace(spec, seed=town_seed(spec.seed, index), town_index=int(index), asset_seed=spec.seed)


def library_seed(spec) -> int:
    """The seed of the asset library :class:`~generator.layout.placement.prototypes.Library` of ``spec``'s town.

    The spec's own seed for a run of one town (``town_index`` None) and for every town when
    ``assets.redraw_every_towns`` is null; else library ``town_index // redraw_every_towns``, seeded
    from the base seed's stream ``("assets", "library", j)`` (53 bits, as :func:`town_seed`).
    """
    base = spec.seed if spec.asset_seed is None else spec.asset_seed
    every = spec.assets.redraw_every_towns
    if spec.town_index is None or every is None:
        return int(base)
    return child_seed(int(base), "assets", "library", int(spec.town_index) // int(every)) >> 10


def town_record(spec) -> dict | None:
    """The ``town`` entry of metadata records: ``{"index", "seed", "base_seed", "every_frames"}``, or None."""
    if spec.town_index is None:
        return None
    return {"index": spec.town_index, "seed": spec.seed, "base_seed": spec.asset_seed,
            "every_frames": redraw_every(spec)}


def spec_for_record(spec, record: dict | None, source: str):
    """The spec of the town a metadata ``record`` (image JSON or ``lidar_meta.json`` ``scene``) came from.

    ``spec`` is the spec as read from its file. A record without ``town`` is of the spec's one
    town; one with ``town`` gives :func:`town_spec`, whose seed must be the recorded one.

    Raises
    ------
    UserError
        One line naming ``source`` when the record's town does not fit ``spec``.
    """
    town = record.get("town") if isinstance(record, dict) else None
    if town is None:
        return spec  # (a spec that differs is caught by its spec_hash)
    if spec.town_index is not None:
        return spec if isinstance(town, dict) and town.get("index") == spec.town_index else \
            _bad(source, "another town", spec)
    index = town.get("index") if isinstance(town, dict) else None
    if type(index) is not int or index < 0:
        raise UserError(f"{source}: town.index: must be an integer >= 0, got {str(index)[:40]}")
    if redraw_every(spec) is None:
        raise UserError(f"{source}: made from town {index} of a spec with town.redraw_every_frames, "
                        f"but {spec.source} re-draws no town")
    out = town_spec(spec, index)
    if town.get("seed") != out.seed:
        _bad(source, f"town {index} of another seed", spec)
    return out


def _bad(source: str, what: str, spec):
    raise UserError(f"{source}: made from {what} than {spec.source} draws (town seed differs)")


RIGHT_ANGLE_TOL_DEG = 1e-6   #: an angle this close to 90 degrees is a right angle: no map at all


def intersection_angle(spec) -> tuple[float, int] | None:
    """The angle (degrees) ``spec``'s two street directions cross at and the lean (+1 or -1) of
    the north-south streets, drawn from ``streets.intersection_angle_deg`` on the stream
    ``("layout", "intersection_angle")``; None for right angles (no ``streets``, or a range at 90).
    The layout maps the town with them (:mod:`generator.layout.mapping.town_map`); metadata records them."""
    streets = getattr(spec, "streets", None)
    if streets is None:
        return None
    lo, hi = streets.intersection_angle_deg
    if lo >= 90.0 - RIGHT_ANGLE_TOL_DEG:
        return None
    g = stream(spec.seed, "layout", "intersection_angle")
    angle = float(g.uniform(lo, hi))
    lean = int(g.choice([-1, 1]))
    return None if angle >= 90.0 - RIGHT_ANGLE_TOL_DEG else (angle, lean)


def angle_record(spec) -> dict:
    """``{"intersection_angle": {"angle_deg", "lean"}}`` for metadata records (images, LiDAR
    sequences) of a town whose streets cross at an angle; ``{}`` for right angles, so the records of
    those towns read as before."""
    drawn = intersection_angle(spec)
    return {} if drawn is None else {"intersection_angle": {"angle_deg": drawn[0], "lean": drawn[1]}}
