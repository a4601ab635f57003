"""The prototype census (generator/world/census.py): distinct meshes per kind, named by their bytes."""

from __future__ import annotations

import numpy as np

from generator.world.census import mesh_digest, prototype_census


def test_the_census_counts_objects_and_distinct_meshes(default_scene):
    census = prototype_census(default_scene)
    for kind in ("car", "person", "building"):
        objs = [o for o in default_scene.objects if o.kind == kind]
        meshes = {default_scene.prototypes[o.prototype].vertices.tobytes() +
                  default_scene.prototypes[o.prototype].faces.tobytes() for o in objs}
        assert census[kind]["objects"] == len(objs) and len(census[kind]["meshes"]) == len(meshes), kind
    assert list(census) == sorted(census)


def test_a_digest_names_the_mesh_not_the_object(default_scene):
    m = next(iter(default_scene.prototypes.values()))
    copy = type(m)(m.vertices.copy(), m.faces.copy(), m.face_class.copy(), m.face_material.copy())
    assert mesh_digest(copy) == mesh_digest(m)
    moved = type(m)(m.vertices + np.array([0.0, 0.0, 1e-6]), m.faces, m.face_class, m.face_material)
    assert mesh_digest(moved) != mesh_digest(m)
