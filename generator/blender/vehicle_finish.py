"""Paint finishes of vehicles, drawn per object: gloss or matte, and how dirty.

The layout draws a vehicle's colour (and whether that paint is metallic) from the fleet palette
(:mod:`generator.layout.placement.appearance`); the finish is drawn here, per object, from a stream
of its own, ``stream(seed, "vehicle_finish", instance_id)``, so every other draw keeps its bytes.
Written as object properties the ``car_paint`` recipe reads (:mod:`generator.blender.recipes_actors`):

* ``ug_paint_matte`` 1 on a satin/matte wrap (no clear coat), share :data:`MATTE_SHARE`;
* ``ug_paint_dirt`` in [0, 1]: Beta(:data:`DIRT_BETA`), mean ~0.3; above ~0.5 a car reads as dirty
  (grime up the doors, dust on the roof), about one car in six.
"""

from __future__ import annotations

from generator.rng import stream

#: classes whose paint takes a finish (the ``car_paint`` / ``car_body`` materials read it)
VEHICLE_CLASSES = frozenset({"car", "truck", "bus", "other_vehicle", "motorcycle", "bicycle", "on_rails"})
MATTE_SHARE = 0.05     #: share of matte paints (wraps and satin finishes are a few per cent of cars)
DIRT_BETA = (1.4, 3.2)  #: Beta(a, b) of the dirt level


def draw_finish(seed: int, instance_id: int) -> dict[str, float]:
    """The finish of the vehicle ``instance_id``: ``{"matte": 0.0 or 1.0, "dirt": float in [0, 1]}``."""
    g = stream(seed, "vehicle_finish", int(instance_id))
    matte = float(g.random() < MATTE_SHARE)
    return {"matte": matte, "dirt": float(g.beta(*DIRT_BETA))}


def apply_finishes(objects, seed: int) -> int:
    """Write the finish of every vehicle among ``objects`` (Blender objects made by
    :func:`generator.blender.geometry.new_object`); returns how many got one."""
    n = 0
    for ob in objects:
        if ob.get("ug_class") in VEHICLE_CLASSES:
            f = draw_finish(seed, ob.pass_index)
            ob["ug_paint_matte"], ob["ug_paint_dirt"] = f["matte"], f["dirt"]
            n += 1
    return n
