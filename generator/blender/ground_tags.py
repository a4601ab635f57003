"""Per-object shader inputs of the ground: where the kerb is, for the gutter of the road recipes.

A street object's mesh is in its segment frame (u along the street, v across, the kerb faces at
``v = +-road_half``), so the asphalt recipe finds the gutter from its object coordinates and the
custom property ``ug_kerb_v`` this module sets (:func:`generator.blender.ground_detail.gutter`).
Towns whose streets cross at an angle have their ground baked into the world frame
(:mod:`generator.layout.mapping.mapped_scene`); there, and for scenes without a street grid, no
property is set and the road has no gutter. Shading only: no geometry or label changes.
"""

from __future__ import annotations

from generator.world.scene import SceneModel

KERB_PROPERTY = "ug_kerb_v"


def tag_kerbs(scene: SceneModel, objects: list) -> int:
    """Set ``ug_kerb_v`` (metres) on the Blender objects of the scene's street segments.

    Parameters
    ----------
    scene : SceneModel
        A :class:`generator.layout.town.Town` (with ``grid``) or any scene (then nothing is set).
    objects : list of bpy.types.Object
        The real objects, in the order of ``scene.objects``.

    Returns
    -------
    int
        How many objects were tagged.
    """
    grid = getattr(scene, "grid", None)
    if grid is None or getattr(scene, "town_map", None) is not None:
        return 0
    kerb = float(grid.road_half)
    n = 0
    for o, ob in zip(scene.objects, objects, strict=True):
        if o.kind == "street":
            ob[KERB_PROPERTY] = kerb
            n += 1
    return n
