"""Export a SceneModel as binary glTF (GLB) for any 3D viewer.

One mesh per native class (named after the class), each with an unlit-looking PBR
material whose base colour is the class colour, so the file reads like the label map in
3D. glTF is y-up: world (x, y, z) is written as (x, z, -y), so viewers show the town
upright. The label proxies are not exported (they are invisible in RGB).
"""

from __future__ import annotations

import numpy as np
import trimesh

from generator.labels import class_table
from generator.world.scene import SceneModel

#: world (z-up) -> glTF (y-up)
Z_UP_TO_Y_UP = np.array([[1, 0, 0, 0], [0, 0, 1, 0], [0, -1, 0, 0], [0, 0, 0, 1]], np.float64)


def class_meshes(scene: SceneModel) -> dict[str, trimesh.Trimesh]:
    """The scene's real geometry split by class: ``{class name: Trimesh}`` (world frame, z up)."""
    table = class_table()
    V, F, C = scene.vertices, scene.faces, scene.face_class
    out = {}
    for cid in np.unique(C):
        faces = F[C == cid]
        used, inverse = np.unique(faces, return_inverse=True)
        name = table.names[int(cid)]
        rgba = np.r_[table.colors[int(cid)], 255].astype(np.uint8)
        material = trimesh.visual.material.PBRMaterial(name=name, baseColorFactor=rgba, metallicFactor=0.0,
                                                       roughnessFactor=0.9, doubleSided=True)
        mesh = trimesh.Trimesh(V[used].astype(np.float64), inverse.reshape(-1, 3), process=False,
                               visual=trimesh.visual.TextureVisuals(material=material))
        out[name] = mesh
    return out


def scene_to_glb(scene: SceneModel) -> bytes:
    """The GLB bytes of ``scene`` (one node per class, y-up)."""
    tscene = trimesh.Scene()
    for name, mesh in class_meshes(scene).items():
        tscene.add_geometry(mesh, node_name=name, geom_name=name, transform=Z_UP_TO_Y_UP)
    return tscene.export(file_type="glb")
