"""One Blender scene per process: build the SceneModel once, render many camera poses."""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from generator.world import rig
from generator.blender import camera, controls, geometry, lighting, materials, night, passes, session
from generator.blender.bpy_guard import bpy
from generator.world.scene import SceneModel
from generator.spec.model import SceneSpec
from generator.spec.render import RenderConfig

log = logging.getLogger(__name__)


@dataclass
class RenderedFrame:
    """What one camera pose yields: the RGB pass and the label passes."""

    rgb: np.ndarray
    labels: passes.LabelPasses
    lighting: dict
    seconds: dict


class Renderer:
    """Owns the Blender scene of one SceneModel.

    Parameters
    ----------
    scene : SceneModel
    spec : SceneSpec
    cfg : RenderConfig
    scratch : Path
        Folder for the temporary EXRs Blender writes (one per pass, deleted after reading).
    """

    def __init__(self, scene: SceneModel, spec: SceneSpec, cfg: RenderConfig, scratch: Path):
        t = time.perf_counter()
        self.model, self.spec, self.cfg = scene, spec, cfg
        self.scratch = Path(scratch)
        self.scratch.mkdir(parents=True, exist_ok=True)
        self.bscene = session.reset()
        self.device = session.configure(self.bscene, cfg)
        self.materials = materials.build_materials(spec.seed)
        self.handles = geometry.build(scene, self.materials, self.bscene.collection)
        self.night_lights, self.night_counts = night.build_lights(scene, self.bscene.collection)
        # Every light and world exists from the start: a render must not depend on earlier renders.
        lighting.ensure_sun(self.bscene)
        night.ensure_moon(self.bscene)
        night.night_world(self.bscene)
        self.k = rig.intrinsics(spec.sensors.camera.hfov_deg, cfg.width, cfg.height)
        controls.apply(self.bscene, controls.DAY_DEFAULTS)
        self.build_seconds = time.perf_counter() - t
        log.info("Blender scene built in %.2f s (%d objects, device %s)", self.build_seconds, len(scene.objects), self.device)

    @property
    def cycles_seconds(self) -> dict[str, float]:
        """Seconds spent inside Cycles' render calls in this process: ``{"rgb": s, "labels": s}``."""
        return dict(passes.CYCLES_SECONDS)

    @property
    def blender_version(self) -> str:
        return bpy.app.version_string

    def set_conditions(self, light, wetness: float = 0.0, puddle_seed: float = 0.0) -> dict:
        """Time of day, lights and wet shaders for the next RGB render.

        Parameters
        ----------
        light : generator.weather.Lighting
            Day (sun position) or night (lit-window fraction).
        wetness : float
            0 (dry) .. 1 (soaked): darker, glossier ground with puddles.
        puddle_seed : float
            Moves the puddle pattern (a new draw per frame).

        Returns
        -------
        dict
            Lighting metadata: sky model, sun or moon, light groups switched on.
        """
        is_night = light.time_of_day == "night"
        night.set_night(self.bscene, self.night_lights, is_night)
        values = dict(controls.DAY_DEFAULTS, wetness=wetness, puddle_seed=puddle_seed)
        if is_night:
            values.update(lit_windows=light.lit_windows, light_windows=1.0, light_street_lamps=1.0,
                          light_vehicle_lights=1.0, light_traffic_lights=1.0)
            info = night.night_world(self.bscene)
            info["lit_windows_fraction"] = light.lit_windows
        else:
            info = lighting.day_world(self.bscene, lighting.DayLight(light.sun_elevation_deg, light.sun_azimuth_deg))
        controls.apply(self.bscene, values)
        groups = [g[len("light_"):] for g, v in values.items() if g.startswith("light_") and v > 0]
        info.update(time_of_day=light.time_of_day, light_groups_on=sorted(groups), wetness=wetness,
                    light_objects={k: v for k, v in self.night_counts.items()} if is_night else {})
        return info

    def place_camera(self, T_world_camera: np.ndarray) -> None:
        """Put the camera at an optical-frame pose (world)."""
        camera.place(self.bscene, T_world_camera, self.spec.sensors.camera.hfov_deg)

    def render_rgb(self, seed: int) -> tuple[np.ndarray, float]:
        """The RGB pass from the current camera under the current conditions: ((H, W, 3) float32, seconds)."""
        return passes.render_rgb(self.bscene, self.handles, self.cfg, seed, self.scratch)

    def render_labels(self) -> passes.LabelPasses:
        """The real and label passes from the current camera (independent of lighting and weather)."""
        return passes.render_labels(self.bscene, self.handles, self.k, self.scratch)

    def render(self, T_world_camera: np.ndarray, seed: int, light_info: dict) -> RenderedFrame:
        """Render the RGB and label passes from one camera pose (optical frame, world)."""
        t0 = time.perf_counter()
        self.place_camera(T_world_camera)
        rgb, rgb_s = self.render_rgb(seed)
        labels = self.render_labels()
        secs = {"rgb_pass": rgb_s, **labels.seconds, "render_total": time.perf_counter() - t0}
        return RenderedFrame(rgb, labels, light_info, secs)

    def evaluated_geometry(self) -> tuple[int, np.ndarray]:
        """Triangle count and world bounds of Blender's evaluated real geometry."""
        return geometry.evaluated_triangles(bpy.context.evaluated_depsgraph_get(), self.handles.real)
