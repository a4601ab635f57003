"""Procedural town layout (pure numpy): streets, lots, placements, routes and frames.

``build_scene(spec) -> Town`` (from :mod:`generator.layout.assemble`) builds the whole town: a
:class:`~generator.world.scene.SceneModel` that keeps the street grid and asset library it was built
from (:class:`~generator.layout.town.Town`), which the traffic drives in.
The wings import downward only, in this order (each may use those above it)::

    network     the street network: grid, cross-sections, roundabouts, closures, one-way streets,
                routes, the design vehicles
    ground      meshes of the ground: roads and markings, sidewalks, intersections, islands, parks, terrain
    lots        blocks cut into lots, districts, the lot band outside the ring road
    placement   what stands where: asset prototypes (the one step that calls the asset builders),
                the placer, and the placement steps
    mapping     a town whose streets cross at an angle: the grid -> world map and the mapped scene
    town        :class:`Town`: the scene and what it was built from
    assemble    ``build_scene``: everything above in order
"""

from generator.layout.assemble import build_scene
from generator.layout.town import Town

__all__ = ["Town", "build_scene"]
