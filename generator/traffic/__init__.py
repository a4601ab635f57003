"""Traffic in motion: the lane graph, signals, vehicles, pedestrians and the ego on one timeline.

:func:`generator.traffic.build.build_world` turns a spec and its static town into a
:class:`generator.world.actors.World`. Pure numpy; deterministic from the spec seed
(streams ``("traffic", ...)``).
"""
