"""urbangen: procedural urban scenes, rendered and scanned from one geometry.

The package is layered (the package map and its import table: ``docs/architecture.md``; the table is
enforced by ``tests/test_architecture.py``):

* a pure numpy core (``spec``, ``labels``, ``geometry``, ``world``, ``layout``, ``traffic``,
  ``lidar``, ``formats``, ``fusion``, ``stats``, ...) that never imports Blender;
* one thin Blender edge, ``generator.blender``, the only place that imports bpy;
* orchestration (``generator.jobs``) and the command line (``generator.commands``, ``generator.cli``).
"""

__version__ = "0.1.0"
