"""SceneModel -> Blender objects.

One mesh datablock per prototype (repeated assets are linked duplicates: instancing),
built with ``foreach_set`` from the very arrays the LiDAR casts against. Every mesh
carries the per-face ``class_id`` (INT) attribute;
meshes with licence plates a UV map ``ug_plate`` (:mod:`generator.blender.plates`), car bodies their seam
properties ``ug_seam_*`` (:mod:`generator.blender.car_seam_shader`);
every object carries its instance id as ``pass_index``, its colour (``attrs["color"]`` or
``attrs["facade_color"]``) in ``color``, ``attrs["roof_color"]`` as the custom
property ``ug_roof_color``, every other ``attrs["<name>_color"]`` as ``ug_<name>_color``,
``attrs["paint_metallic"]`` as ``ug_paint_metallic`` and ``ug_outfit`` = 1 where a person's
colours are given (see :mod:`generator.blender.recipes_actors`).
Label proxies live in their own collection, hidden in the RGB pass.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from generator.blender.bpy_guard import bpy, mathutils
from generator.blender.car_seam_shader import seam_properties
from generator.blender.plates import plate_uv
from generator.geometry import Mesh
from generator.materials import material_table
from generator.world.scene import SceneModel

#: Materials shaded smooth (organic shapes); everything else is flat (hard surfaces).
PLATE_UV = "ug_plate"  #: UV map of meshes with licence plates (:func:`generator.blender.plates.plate_uv`)
SMOOTH_MATERIALS = frozenset({"leaves", "hedge_leaves", "hedge_body", "bark", "bark_plane", "leaf_shade",
                              "skin", "hair", "clothing", "rubber", "car_body", "clothing_bottom"})


@dataclass
class BlenderScene:
    """Handles to what :func:`build` created."""

    real: bpy.types.Collection
    proxies: bpy.types.Collection
    objects: list
    proxy_objects: list
    meshes: dict


def mesh(name: str, m: Mesh, materials: list) -> bpy.types.Mesh:
    """A Blender mesh of ``m``: its faces, material slots, flat/smooth shading and per-face ``class_id``."""
    me = bpy.data.meshes.new(name)
    n_v, n_f = len(m.vertices), m.n_faces
    me.vertices.add(n_v)
    me.vertices.foreach_set("co", m.vertices.astype(np.float32).ravel())
    me.loops.add(3 * n_f)
    me.loops.foreach_set("vertex_index", m.faces.astype(np.int32).ravel())
    me.polygons.add(n_f)
    me.polygons.foreach_set("loop_start", np.arange(0, 3 * n_f, 3, dtype=np.int32))
    used = np.unique(m.face_material)
    for mid in used:
        me.materials.append(materials[int(mid)])
    slot = np.searchsorted(used, m.face_material).astype(np.int32)
    me.polygons.foreach_set("material_index", slot)
    table = material_table()
    smooth = np.isin(m.face_material, [table.id(n) for n in SMOOTH_MATERIALS])
    me.attributes.new("sharp_face", "BOOLEAN", "FACE").data.foreach_set("value", ~smooth)
    me.attributes.new("class_id", "INT", "FACE").data.foreach_set("value", m.face_class.astype(np.int32))
    plate = m.face_material == table.id("licence_plate")
    if plate.any():                                   # where on its plate each corner lies (the registration)
        me.uv_layers.new(name=PLATE_UV).data.foreach_set("uv", plate_uv(m.vertices, m.faces, plate).ravel())
    for key, value in seam_properties(m.anchors).items():  # a car body's panel gaps, read by its paint
        me[key] = list(value) if len(value) > 1 else value[0]
    me.update()
    return me


def build(scene: SceneModel, materials: list, parent: bpy.types.Collection) -> BlenderScene:
    """Create every object of ``scene`` under ``parent``.

    Parameters
    ----------
    scene : SceneModel
    materials : list of bpy.types.Material
        Indexed by material id (see :func:`generator.blender.materials.build_materials`).
    parent : bpy.types.Collection
        Usually the scene's master collection.
    """
    real = bpy.data.collections.new("urbangen_real")
    proxies = bpy.data.collections.new("urbangen_proxies")
    parent.children.link(real)
    parent.children.link(proxies)
    meshes = {key: mesh(key, m, materials) for key, m in scene.prototypes.items()}
    proxy_meshes = {key: mesh("hull:" + key, m, materials) for key, m in scene.proxies.items()}
    objs, hulls = [], []
    for o in scene.objects:
        ob = new_object(o.name, meshes[o.prototype], o.transform, o.instance_id, o.cls, o.attrs)
        real.objects.link(ob)
        objs.append(ob)
        if o.proxy is not None:
            hb = new_object(o.name + "_hull", proxy_meshes[o.proxy], o.transform, o.instance_id)
            proxies.objects.link(hb)
            hulls.append(hb)
    return BlenderScene(real, proxies, objs, hulls, meshes)


def new_object(name: str, data: bpy.types.Mesh, transform: np.ndarray, instance_id: int, cls: str | None = None,
               attrs: dict | None = None) -> bpy.types.Object:
    """An object of mesh ``data`` at ``transform`` ((4, 4) world-from-local) carrying its instance id as
    ``pass_index``; a real object (``cls`` given) also its colour and class (see the module docstring)."""
    ob = bpy.data.objects.new(name, data)
    ob.matrix_world = _matrix(transform)
    ob.pass_index = int(instance_id)
    if cls is not None:
        attrs = attrs or {}
        color = attrs.get("color", attrs.get("facade_color", (1.0, 1.0, 1.0)))
        ob.color = (float(color[0]), float(color[1]), float(color[2]), 1.0)
        ob["ug_roof_color"] = [float(c) for c in attrs.get("roof_color", (1.0, 1.0, 1.0))]
        for key, value in attrs.items():
            if key.endswith("_color") and key not in ("facade_color", "roof_color"):
                ob["ug_" + key] = [float(c) for c in value]
        ob["ug_paint_metallic"] = float(attrs.get("paint_metallic", 0.0))
        ob["ug_outfit"] = 1.0 if "skin_color" in attrs else 0.0
        ob["ug_class"] = cls
        ob["ug_lights_on"] = 1.0 if lights_on(attrs) else 0.0
    return ob


def lights_on(attrs: dict) -> bool:
    """Vehicle lamps (lenses and their spot lights) burn on vehicles in use (moving traffic, ridden,
    at a stop), not on parked or racked ones."""
    return attrs.get("placement") not in ("parked", "rack")


def _matrix(t: np.ndarray) -> mathutils.Matrix:
    return mathutils.Matrix([list(map(float, row)) for row in t])


RAY_FLAGS = ("visible_camera", "visible_shadow", "visible_diffuse", "visible_glossy", "visible_transmission",
             "visible_volume_scatter")


def set_proxies_visible(bs: BlenderScene, visible: bool) -> None:
    """Show the label proxies (label pass) or make them invisible to every ray (RGB pass: no shading,
    no shadow, no reflection).

    Ray-visibility flags rather than hiding the collection: the proxies stay in Cycles' scene, so
    switching between passes does not re-sync it (label passes 0.97 -> 0.74 s per preview frame).
    """
    if bs.proxy_objects and bs.proxy_objects[0].visible_camera == visible:
        return
    for ob in bs.proxy_objects:
        for flag in RAY_FLAGS:
            setattr(ob, flag, visible)


def evaluated_triangles(depsgraph, collection: bpy.types.Collection) -> tuple[int, np.ndarray]:
    """Triangle count and (2, 3) world bounds of the evaluated objects of ``collection``.

    Used by tests to hold Blender's geometry equal to the SceneModel.
    """
    n = 0
    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
    for ob in collection.objects:
        ev = ob.evaluated_get(depsgraph)
        me = ev.to_mesh()
        me.calc_loop_triangles()
        n += len(me.loop_triangles)
        co = np.empty(len(me.vertices) * 3, np.float32)
        me.vertices.foreach_get("co", co)
        co = co.reshape(-1, 3) @ np.array(ev.matrix_world)[:3, :3].T + np.array(ev.matrix_world)[:3, 3]
        if len(co):
            lo, hi = np.minimum(lo, co.min(0)), np.maximum(hi, co.max(0))
        ev.to_mesh_clear()
    return n, np.stack([lo, hi])
