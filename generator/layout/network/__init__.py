"""The street network: the grid of streets, their cross-sections, roundabouts, closed and one-way
streets, the routes the ego drives, and the design vehicles they are sized for.

Modules import downward only, in this order (each may use those above it)::

    design_vehicle, measures      constants: the vehicles streets are sized for; bands and steps of a street
    cycles                        the node cycles of routes 0 and 1 (no geometry)
    one_way                       which way a one-way street runs (connected network, routes' directions)
    cross_sections                the street types and their draws
    rings                         a roundabout's ring geometry and the paths round it
    grid                          :class:`Grid`, :class:`Segment`: the streets and the areas they cover
    roundabouts, closures         which nodes are roundabouts, which segments are closed (draws)
    draw                          :func:`make_grid`: the grid of a spec, every draw in order
    routes                        the ego's closed routes through the grid
"""

from generator.layout.network.draw import make_grid
from generator.layout.network.grid import Grid, Segment

__all__ = ["Grid", "Segment", "make_grid"]
