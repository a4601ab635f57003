"""urbangen: procedural urban scenes, rendered and scanned from one geometry.

The package is layered (see ``DESIGN.md`` in the shared folder):

* a pure numpy core (``spec``, ``labels``, ``layout``, ``scene``, ``lidar``,
  ``formats``, ``fusion``, ``stats``) that never imports Blender;
* one thin Blender edge, ``generator.blender``, the only place that imports bpy;
* the command line, ``generator.cli``.
"""

__version__ = "0.1.0"
