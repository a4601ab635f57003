"""The world: the assembled static scene, the sensor rig and the ego's drive in time.

* :mod:`.scene` -- :class:`SceneModel`, the triangles and labels both sensors use;
* :mod:`.trajectory` -- the ego's pose as a function of time;
* :mod:`.rig` -- every sensor's mount and intrinsics, the frame plan and sweep poses.
"""
