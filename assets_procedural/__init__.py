"""Procedural asset builders (pure numpy/trimesh), one module per family.

Every builder returns a :class:`generator.geometry.Mesh` in its own local frame:
metres, z up, the origin on the ground at the centre of the footprint, +x the
object's forward/length axis. Layout code places it with a 4x4 transform.
"""
