"""The ground of the town as meshes: roads with their markings, sidewalks and kerbs, intersections,
roundabout islands, the parks of closed streets, and the terrain to the horizon.

Pure numpy, built on the street network (:mod:`generator.layout.network`). Modules import downward
only, in this order::

    surfaces          flat rectangles, dashes and kerb slabs: the pieces every ground mesh is made of
    markings          crosswalks, stop and give-way lines, one-way markings and arrows (segment frame)
    islands           a roundabout's island
    roads             a segment's road surface (plain, varied strips, shared streets)
    sidewalks         a segment's kerbs and sidewalks (with tree pits)
    parks             the pocket park of a closed segment
    intersections     an intersection's asphalt square and corner pieces (islands and parks included)
    terrain           the terrain margin and the ground to the horizon
"""
