"""Carry a town laid out on the grid into the world of its :class:`~generator.layout.mapping.town_map.TownMap`.

:func:`map_scene` turns the grid-frame :class:`~generator.world.scene.SceneModel` into the one
every sensor sees: shaped objects (ground pieces, buildings, hedges, fences, walls, rails) get
their map baked into a prototype of their own (a Blender object transform cannot hold a shear)
under a rigid frame that keeps their local x axis; rigid objects keep their prototype under
:meth:`~generator.layout.mapping.town_map.TownMap.rigid`. Paths are mapped sample by sample and their
arc lengths re-measured. The grid-frame scene stays reachable as ``scene.layout`` (the traffic
is simulated there, :func:`generator.traffic.build.build_world`) and the map as
``scene.town_map`` (:class:`generator.layout.town.Town`).
"""

from __future__ import annotations

import numpy as np

from generator.geometry import Mesh
from generator.geometry.boxes import box_of
from generator.labels import class_table
from generator.layout.mapping.town_map import TownMap
from generator.layout.placement.keepout import Keepout
from generator.world.scene import Path, SceneModel, SceneObject


class MappedLayoutError(RuntimeError):
    """A mapped object ends up too close to a route (a bug of the placement checks)."""


def _bake(mesh: Mesh, transform: np.ndarray) -> tuple[Mesh, np.ndarray]:
    """``mesh`` under the (4, 4) affine ``transform``, in a rigid frame of its own: (mesh, frame).

    The frame (origin and yaw of ``transform``'s mapped local x axis) keeps the object's own axes
    for what Blender shades in object coordinates (bricks along a wall, pavers along a street);
    only the shear and stretch are baked into the vertices."""
    yaw = float(np.arctan2(transform[1, 0], transform[0, 0]))
    c, s = np.cos(yaw), np.sin(yaw)
    T = np.eye(4)
    T[:2, :2] = [[c, -s], [s, c]]
    T[:3, 3] = transform[:3, 3]
    inv = np.eye(4)
    inv[:3, :3] = T[:3, :3].T
    inv[:3, 3] = -T[:3, :3].T @ T[:3, 3]
    return mesh.transformed(inv @ transform), T


def square_bay_lines(mesh: Mesh, k: float, lane_half: float) -> Mesh:
    """``mesh`` (a street's road, segment frame) with each marking rectangle that lies wholly in a
    side strip (``|v| > lane_half``: parking bay lines) sheared about its centre by ``u += k (v - v_c)``,
    so that after the map it is square to the kerb instead of parallel to the cross street."""
    faces = mesh.faces[mesh.face_class == class_table().id("road_marking")]
    if not len(faces):
        return mesh
    v = mesh.vertices.copy()
    quad = faces.min(1)                                  # a rectangle's two triangles share its first vertex
    for first in np.unique(quad):
        idx = np.unique(faces[quad == first])
        if len(idx) != 4 or (np.abs(v[idx, 1]) <= lane_half).any():
            continue
        vc = v[idx, 1].mean()
        v[idx, 0] += k * (v[idx, 1] - vc)
    return Mesh(v, mesh.faces, mesh.face_class, mesh.face_material, dict(mesh.anchors))


def map_path(path: Path, tmap: TownMap) -> Path:
    """``path`` in the world: samples mapped, headings turned, arc lengths re-measured."""
    pts = tmap.xy(path.points)
    s = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))]
    return Path(path.name, pts, tmap.yaw(path.headings), s, path.closed)


def map_scene(layout: SceneModel, tmap: TownMap, shaped: set[int]) -> SceneModel:
    """The world scene of the grid-frame ``layout``.

    Parameters
    ----------
    layout : SceneModel
        Built in the grid frame (:func:`generator.layout.assemble.build_scene`).
    tmap : TownMap
    shaped : set of int
        Indices of the objects mapped point by point; the others are rigid.

    Returns
    -------
    SceneModel
        Same objects (names, classes, instance ids, order), world transforms and boxes; a shaped
        object's prototype (and label proxy) is baked and keyed ``<name>_mapped``.
    """
    prototypes, proxies, objects, bounds = {}, {}, [], {}
    for o in layout.objects:
        if o.index in shaped:
            Ta = tmap.affine(o.transform)
            mesh = layout.prototypes[o.prototype]
            if o.kind == "street":
                mesh = square_bay_lines(mesh, tmap.square_shear(o.transform), tmap.lane_half)
            mesh, T = _bake(mesh, Ta)
            key = f"{o.name}_mapped"     # object names are unique; no prototype key ends so
            prototypes[key] = mesh
            proxy = None
            if o.proxy is not None:
                proxies[key], _ = _bake(layout.proxies[o.proxy], Ta)
                proxy = key
            objects.append(SceneObject(o.index, o.name, o.kind, o.cls, o.instance_id, key, T,
                                       box_of(*mesh.bounds(), T), proxy, dict(o.attrs)))
            continue
        T = tmap.rigid(o.transform)
        if o.prototype not in prototypes:       # instanced: shared, bounds taken once
            prototypes[o.prototype] = layout.prototypes[o.prototype]
            bounds[o.prototype] = layout.prototypes[o.prototype].bounds()
        if o.proxy is not None:
            proxies.setdefault(o.proxy, layout.proxies[o.proxy])
        objects.append(SceneObject(o.index, o.name, o.kind, o.cls, o.instance_id, o.prototype, T,
                                   box_of(*bounds[o.prototype], T), o.proxy, dict(o.attrs)))
    (x0, y0), (x1, y1) = layout.bounds
    corners = tmap.xy(np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]]))
    extent = np.stack([corners.min(0), corners.max(0)])
    return SceneModel(layout.seed, layout.spec_hash, extent, prototypes, proxies, objects,
                      [map_path(p, tmap) for p in layout.paths])


def verify_world_routes(scene: SceneModel, layout: SceneModel, tmap: TownMap, first: int, shaped: set[int],
                        limit: float, last: int | None = None) -> None:
    """Raise :class:`MappedLayoutError` unless every route sample of the world ``scene`` (the map
    ``tmap`` of the grid-frame ``layout``) keeps ``limit`` metres (2D) from each placed object (index
    ``first`` on, up to ``last``, the far city excluded): a rigid one's box, a shaped one's mapped footprint
    (the parallelogram its grid box becomes)."""
    for path in scene.paths:
        keep = Keepout(path.points[:, :2], limit)
        for o in scene.objects[first:last]:
            if o.index in shaped:
                d = keep.polygon_distance(tmap.xy(layout.objects[o.index].box.corners_xy()))
            else:
                d = keep.distance(o.box)
            if d < limit:
                raise MappedLayoutError(f"{path.name}: {o.name} is {d:.2f} m from the route (< {limit:.2f} m)")
