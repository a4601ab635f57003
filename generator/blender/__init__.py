"""The Blender edge: the only package that imports bpy.

It translates a :class:`generator.scene.SceneModel` into a Blender scene, renders the
RGB and label passes with Cycles and hands numpy arrays back to the pure core. Import
bpy only through :mod:`generator.blender.bpy_guard`. Run it in a spawned worker
process (never fork after importing bpy): see :mod:`generator.blender.worker`.
"""
