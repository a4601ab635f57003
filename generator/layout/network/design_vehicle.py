"""The design vehicles: the boxes the streets, roundabouts, routes and lane conflicts are sized for.

One home for the sizes every part of the town is measured against (lengths in metres):

* :data:`EGO_HALF_WIDTH_M`: half the width the layout keeps free for the ego on its route (the
  route keep-out, the median and the roundabout island clearances): wider than the simulated ego's
  body (:data:`EGO_SIZE_M`, 1.9 m) by its mirrors and a margin;
* :data:`EGO_SIZE_M`: the simulated ego's box (length, width) in the moving traffic;
* :data:`STANDARD_CAR_M`: the standard car (length, width): conflict tables of the lane graph, the
  kerb check of a roundabout's paths;
* :data:`DESIGN_VEHICLES_M`: the largest boxes that drive a roundabout's ring (the raised centre
  keeps clear of them);
* :data:`MIN_RADIUS_M`, :data:`RIGHT_RADIUS_M`: the tightest turn any route or connector makes and
  the preferred right-turn radius (left turns are concentric, two lane offsets wider).
"""

EGO_HALF_WIDTH_M = 1.2        #: half the width the layout keeps free for the ego that drives the routes
EGO_SIZE_M = (4.6, 1.9)       #: the simulated ego's box: length, width
STANDARD_CAR_M = (4.8, 2.1)   #: the standard car: length, width
#: the largest boxes (length, width) that drive a roundabout's ring: a 12 m bus, a 4.3 m wide slewed excavator
DESIGN_VEHICLES_M = ((12.0, 2.55), (6.0, 4.3))
RIGHT_RADIUS_M = 6.0          #: preferred right-turn radius (left turns are concentric, 2 lane offsets wider)
MIN_RADIUS_M = 5.0            #: the tightest turn of any route or connector
