"""Scene-wide shader switches, stored as scene custom properties.

Materials read them with ``VIEW_LAYER`` attribute nodes; setting them and tagging the
scene updates the next render without rebuilding any shader (persistent data stays).
"""

from __future__ import annotations

#: Logical name -> scene custom property.
CONTROL = {
    "wetness": "ug_wetness",            # 0 dry .. 1 soaked (shader wetness of ground materials)
    "puddle_seed": "ug_puddle_seed",    # moves the puddle/ripple noise per image
    "lit_windows": "ug_lit_windows",    # fraction of windows lit (night)
    "light_windows": "ug_light_windows",
    "light_street_lamps": "ug_light_street_lamps",
    "light_vehicle_lights": "ug_light_vehicle_lights",
    "light_traffic_lights": "ug_light_traffic_lights",
}

#: The label switch: 0 in the RGB pass, 1 in the label passes (every material then emits its
#: label, see :mod:`generator.blender.materials`); set by :mod:`generator.blender.session`.
LABEL = "ug_label"

#: Values for a dry, clear day.
DAY_DEFAULTS = {
    "wetness": 0.0, "puddle_seed": 0.0, "lit_windows": 0.0, "light_windows": 0.0,
    "light_street_lamps": 0.0, "light_vehicle_lights": 0.0, "light_traffic_lights": 1.0,
}


def apply(scene, values: dict) -> None:
    """Set the named controls on ``scene`` (a bpy Scene) and tag it for the next render."""
    for name, value in values.items():
        scene[CONTROL[name]] = float(value)
    scene.update_tag()
