"""Traffic in motion: the lane graph, signals, vehicles, pedestrians and the ego on one timeline.

:func:`build_world` (:mod:`generator.traffic.build`) turns a spec and its static town into a
:class:`generator.world.actors.World`. Pure numpy; deterministic from the spec seed (streams
``("traffic", ...)``). The sub-packages import downward only: ``lanes`` (the lane graph, one-way
streets and roundabouts in it, conflicts, signals, clearances), ``vehicles`` (the fleet and the
car-following simulation), ``pedestrians`` (walkways, walkers and standers); ``movers`` and
``mapped_tracks`` hold what every simulation hands to ``build``.
"""

from generator.traffic.build import build_world

__all__ = ["build_world"]
