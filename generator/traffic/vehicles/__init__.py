"""Vehicles: the moving fleet's prototypes (:mod:`.fleet`) and the car-following simulation on the
lane graph with the ego among them (:mod:`.sim`)."""
