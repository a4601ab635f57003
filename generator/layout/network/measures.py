"""Measures of a street: kerbs, the bands along a segment, bays, arm directions.

Bands along a segment are in metres from the intersection edge (``u``, see
:class:`generator.layout.network.grid.Segment`). Arms of a node are numbered 0 east, 1 north,
2 west, 3 south.
"""

import numpy as np

CURB_WIDTH_M = 0.18
MARK_Z_M = 0.005           #: markings float this far above the asphalt (no z-fighting)
CROSSWALK_U = (0.6, 3.6)   #: crosswalk band, metres from the intersection edge
STOP_U = (4.6, 5.0)        #: stop line band, metres from the intersection edge
PARKING_START_U = 7.0      #: parking strips start this far from the intersection edge
BAY_M = 6.0                #: parking bay length
ARM_STEP = ((1, 0), (0, 1), (-1, 0), (0, -1))   #: node index step of arms east, north, west, south
ARM_DIRS = np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]])  #: east, north, west, south
MIN_BLOCK_M = 15.0         #: blocks never shrink below this (jitter can be large)
MIN_OUTER_DEPTH_M = 15.0   #: the lot band outside the outer ring road is at least this deep
TREE_PIT_M = 1.2           #: side of the soil square around a street tree
APRON_H_M = 0.05           #: a roundabout island's mountable apron (:mod:`generator.layout.network.rings`)
