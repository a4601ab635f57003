"""The Blender edge: the only package that imports bpy.

It translates a :class:`generator.world.scene.SceneModel` into a Blender scene, renders the
RGB and label passes with Cycles and hands numpy arrays back to the pure core. Import
bpy only through :mod:`generator.blender.bpy_guard`. Its entry is
:class:`generator.blender.renderer.Renderer`: a scene and a camera pose in, passes out. It
imports nothing from orchestration (``jobs``, ``commands``) or the layout; run it in a
spawned worker process (never fork after importing bpy): see :mod:`generator.jobs.worker`.
"""
