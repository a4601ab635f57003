"""The lanes vehicles drive: the lane graph, one-way streets and roundabouts in it, which connectors
conflict, the signals, and the clearances that keep vehicles apart at turns and rings.

Modules import downward only, in this order (each may use those above it)::

    paths             lane pieces and connector curves (straight, quarter circle, cubic merge)
    edges             :class:`~generator.traffic.lanes.edges.Edge`, one directed lane or connector
    conflicts         which connectors of a node conflict (padded standard-car boxes swept along them)
    roundabouts       the same at a roundabout; its give-way rules' distances and times
    one_way           one-way streets in the graph (lanes turned round, connectors rebuilt)
    graph             :class:`~generator.traffic.lanes.graph.LaneGraph`
    signals, speed_caps, clearance, ring_clearance, turn_clearance, crosswalks
                      signal phases; speed limits per edge; lanes and turns static objects block;
                      where vehicles wait so turning long vehicles clear them; which crosswalks a
                      vehicle's box passes over on a connector (it waits until nobody is on them)
"""
