"""One Blender scene per process: build the SceneModel (and the world's actors) once, render many
camera poses at many times."""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from generator.blender import actors, camera, controls, geometry, lighting, materials, motion, night, passes, session
from generator.blender.bpy_guard import bpy
from generator.blender.ground_tags import tag_kerbs
from generator.blender.plates import apply_plates
from generator.blender.vehicle_finish import apply_finishes
from generator.spec.model import SceneSpec
from generator.spec.render import RenderConfig
from generator.weather import LIT_TIMES
from generator.world import rig
from generator.world.actors import World
from generator.world.scene import SceneModel

log = logging.getLogger(__name__)


@dataclass
class RenderedFrame:
    """What one camera pose yields: the RGB pass and the label passes."""

    rgb: np.ndarray
    labels: passes.LabelPasses
    lighting: dict
    seconds: dict


class Renderer:
    """Owns the Blender scene of one SceneModel and the actors of its world.

    Parameters
    ----------
    scene : SceneModel
    spec : SceneSpec
    cfg : RenderConfig
    scratch : Path
        Folder for the temporary EXRs Blender writes (one per pass, deleted after reading).
    world : World, optional
        The town in time: its actors are rendered where their tracks are at the time set by
        :meth:`set_time`. None, or a world without actors: the static town, exactly as before.

    Notes
    -----
    Per image: :meth:`set_time` (actors), :meth:`place_camera` (with the camera's poses at
    :meth:`shutter_times` when motion blur is on), then :meth:`render_labels` (always sharp, at the
    instant) and :meth:`render_rgb` (blurred over the exposure when ``cfg.motion_blur.enabled``).
    """

    def __init__(self, scene: SceneModel, spec: SceneSpec, cfg: RenderConfig, scratch: Path,
                 world: World | None = None):
        t = time.perf_counter()
        self.model, self.spec, self.cfg = scene, spec, cfg
        self.scratch = Path(scratch)
        self.scratch.mkdir(parents=True, exist_ok=True)
        self.bscene = session.reset()
        self.device = session.configure(self.bscene, cfg)
        self.materials = materials.build_materials(spec.seed)
        self.handles = geometry.build(scene, self.materials, self.bscene.collection)
        tag_kerbs(scene, self.handles.objects)
        self.night_lights, self.night_counts = night.build_lights(scene, self.bscene.collection)
        self.world = world
        self.actors = None
        if world is not None and world.actors:
            self.actors = actors.build(world, self.materials, self.handles)
            self.night_counts["headlights"] += actors.headlights(self.actors, night.headlight, self.night_lights)
        vehicles = self.handles.objects + (self.actors.objects if self.actors else [])
        apply_finishes(vehicles, spec.seed)
        apply_plates(vehicles, spec.seed)
        # Every light and world exists from the start: a render must not depend on earlier renders.
        lighting.ensure_sun(self.bscene)
        night.ensure_moon(self.bscene)
        night.night_world(self.bscene)
        self.k = rig.intrinsics(spec.sensors.camera.hfov_deg, cfg.width, cfg.height)
        controls.apply(self.bscene, controls.DAY_DEFAULTS)
        self.build_seconds = time.perf_counter() - t
        log.info(
            "Blender scene built in %.2f s (%d objects, device %s)", self.build_seconds, len(scene.objects), self.device
        )

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
            Day (sun, clouds), dusk (low sun, clouds, lit windows) or night (lit windows, clouds).
        wetness : float
            0 (dry) .. 1 (soaked): darker, glossier ground with puddles.
        puddle_seed : float
            Moves the puddle pattern (a new draw per frame).

        Returns
        -------
        dict
            Lighting metadata: sky model, sun or moon, light groups switched on.
        """
        lit = light.time_of_day in LIT_TIMES
        night.set_night(self.bscene, self.night_lights, lit)
        values = dict(controls.DAY_DEFAULTS, wetness=wetness, puddle_seed=puddle_seed)
        if lit:
            values.update(lit_windows=light.lit_windows, **{"light_" + k: v for k, v in night.EMISSION_SCALE.items()})
        if light.time_of_day == "night":
            info = night.night_world(self.bscene, light.overcast, light.cloud_seed)
        else:
            info = lighting.day_world(self.bscene, lighting.DayLight(
                light.sun_elevation_deg, light.sun_azimuth_deg, light.cloud_cover, light.cloud_seed, light.overcast))
        if lit:
            info.update(night.lights_record(), lit_windows_fraction=light.lit_windows)
        sky_map(self.bscene.world, self.cfg.sky_map_resolution)
        controls.apply(self.bscene, values)
        groups = [g[len("light_"):] for g, v in values.items() if g.startswith("light_") and v > 0]
        info.update(time_of_day=light.time_of_day, light_groups_on=sorted(groups), wetness=wetness,
                    light_objects={k: v for k, v in self.night_counts.items()} if lit else {})
        return info

    @property
    def motion_blur(self) -> dict:
        """The motion-blur settings images are rendered with (for metadata)."""
        mb = self.cfg.motion_blur
        return {"enabled": mb.enabled, "shutter_s": mb.shutter_s if mb.enabled else 0.0,
                "method": "cycles" if mb.enabled else "none"}

    def shutter_times(self, t: float) -> np.ndarray:
        """(3,) float64: when the shutter opens, the image instant ``t`` and when it closes, seconds
        (all ``t`` with motion blur off)."""
        half = self.cfg.motion_blur.shutter_s / 2 if self.cfg.motion_blur.enabled else 0.0
        return np.array([t - half, t, t + half])

    def set_time(self, t: float) -> None:
        """Pose every actor at time ``t`` (seconds on the world's timeline) and over the exposure."""
        if self.actors is not None:
            self.actors.pose(self.shutter_times(t))
            motion.set_frame(self.bscene)

    def place_camera(self, T_world_camera: np.ndarray, shutter: np.ndarray | None = None) -> None:
        """Put the camera at an optical-frame pose (world).

        Parameters
        ----------
        T_world_camera : (4, 4) float64
            Pose at the image instant.
        shutter : (2, 4, 4) float64, optional
            Poses when the shutter opens and closes (at :meth:`shutter_times`), for motion blur from
            the camera's own motion; ignored when the config's motion blur is off.
        """
        moving = shutter if self.cfg.motion_blur.enabled else None
        camera.place(self.bscene, T_world_camera, self.spec.sensors.camera.hfov_deg, moving)

    def render_rgb(self, seed: int) -> tuple[np.ndarray, float]:
        """The RGB pass from the current camera under the current conditions: ((H, W, 3) float32, seconds)."""
        return passes.render_rgb(self.bscene, self.handles, self.cfg, seed, self.scratch)

    def render_labels(self) -> passes.LabelPasses:
        """The real and label passes from the current camera (independent of lighting and weather)."""
        return passes.render_labels(self.bscene, self.handles, self.k, self.scratch, self.cfg.label_supersample)

    def render_labels_batch(self, poses) -> list[passes.LabelPasses]:
        """The real and label passes of several images behind one switch of the render state.

        Parameters
        ----------
        poses : sequence of callables
            Each poses the camera and actors for one image (e.g. :func:`generator.jobs.exposure.expose`
            bound to its time); see :func:`generator.blender.passes.render_label_batch`.
        """
        return passes.render_label_batch(self.bscene, self.handles, self.k, self.scratch, poses,
                                         self.cfg.label_supersample)

    def render(self, T_world_camera: np.ndarray, seed: int, light_info: dict,
               shutter: np.ndarray | None = None) -> RenderedFrame:
        """Render the RGB and label passes from one camera pose (optical frame, world; ``shutter`` as
        in :meth:`place_camera`) at the time last set by :meth:`set_time`."""
        t0 = time.perf_counter()
        self.place_camera(T_world_camera, shutter)
        rgb, rgb_s = self.render_rgb(seed)
        labels = self.render_labels()
        secs = {"rgb_pass": rgb_s, **labels.seconds, "render_total": time.perf_counter() - t0}
        return RenderedFrame(rgb, labels, light_info, secs)

    def evaluated_geometry(self) -> tuple[int, np.ndarray]:
        """Triangle count and world bounds of Blender's evaluated real geometry."""
        return geometry.evaluated_triangles(bpy.context.evaluated_depsgraph_get(), self.handles.real)


def sky_map(world, resolution: int) -> None:
    """Give ``world`` an importance map ``resolution`` pixels wide (0: Cycles' automatic one).

    Set only when it differs: a world kept from the image before (:func:`generator.blender.sky.kept_world`)
    keeps its map, which Cycles would rebuild if a setting were written again.
    """
    w = world.cycles
    method, res = ("MANUAL", resolution) if resolution else ("AUTOMATIC", w.sample_map_resolution)
    if w.sampling_method != method or w.sample_map_resolution != res:
        w.sampling_method, w.sample_map_resolution = method, res
