"""Pedestrians: walkers on the walk network and people standing, clear of every static object.

Modules import downward only: ``clear`` (bodies, obstacles, boxes), ``lines`` (walking lines along
the sidewalks and over crosswalks), ``walkways`` (the walk network), ``zones`` (where walkers' paths
conflict), ``net`` and ``rules`` (the network walkers plan on and its right of way), ``sim`` (walking),
``shared`` (people on shared streets), then ``simulate`` (:func:`~.simulate.simulate_pedestrians`).
"""
