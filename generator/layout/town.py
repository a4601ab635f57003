"""The town :func:`generator.layout.build_scene` returns: the scene both sensors use, and the street
grid and asset library it was built from, so the traffic drives in this town instead of building
it again (:func:`generator.traffic.build_world`).

A :class:`Town` is a :class:`~generator.world.scene.SceneModel` (everything that takes a scene takes
it) with four more fields. The world layer knows nothing of grids or libraries; the layout, which
makes both, adds them here.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

from generator.layout.mapping.town_map import TownMap
from generator.layout.network.grid import Grid
from generator.layout.placement.prototypes import Library
from generator.world.scene import SceneModel


@dataclass(eq=False)
class Town(SceneModel):
    """A built town: the scene, and what it was built from.

    Attributes
    ----------
    grid : Grid
        The street grid (grid frame), roundabouts, closures and cross-sections included.
    library : Library
        The asset library every prototype of the town came from, seeded by
        :func:`generator.spec.towns.library_seed` (a re-drawn town's own library, or the one it shares
        with its neighbours, ``assets.redraw_every_towns``; else the spec's ``seed``). The moving
        traffic draws its vehicles and people from it too.
    town_map : TownMap or None
        The grid -> world map of a town whose streets cross at an angle other than 90 degrees;
        None when they cross at right angles (grid and world are the same frame).
    layout : SceneModel or None
        With a ``town_map``: the same town in the grid frame, where the traffic is simulated.
    """

    grid: Grid = field(kw_only=True, repr=False, compare=False)
    library: Library = field(kw_only=True, repr=False, compare=False)
    town_map: TownMap | None = field(default=None, kw_only=True, repr=False, compare=False)
    layout: SceneModel | None = field(default=None, kw_only=True, repr=False, compare=False)

    @classmethod
    def of(cls, scene: SceneModel, grid: Grid, library: Library, town_map: TownMap | None = None,
           layout: SceneModel | None = None) -> Town:
        """The town of ``scene`` (its fields shared, not copied) built from ``grid`` and ``library``."""
        base = {f.name: getattr(scene, f.name) for f in dataclasses.fields(SceneModel)}
        return cls(**base, grid=grid, library=library, town_map=town_map, layout=layout)
