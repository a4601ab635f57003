"""Render configs (``render_configs/*.yaml``): typed, validated like scene specs."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

from generator.errors import SpecError
from generator.spec.load import canonical_hash
from generator.spec.model import build
from generator.spec.validate import load_schema, read_document, validate, with_defaults

#: Folder of the shipped presets (``test``, ``preview``, ``paper``), at the repository root.
PRESET_DIR = Path(__file__).resolve().parents[2] / "render_configs"


@dataclass(frozen=True)
class MotionBlur:
    """Motion blur of the RGB pass (``motion_blur`` in the schema).

    Attributes
    ----------
    enabled : bool
        Off: a sharp snapshot at the image time, exactly as before the switch existed.
    shutter_s : float
        Exposure time, seconds, centred on the image time.
    """

    enabled: bool = False
    shutter_s: float = 0.01


@dataclass(frozen=True)
class RenderConfig:
    """Cycles settings for one dataset (see ``schemas/render.schema.json``)."""

    name: str
    resolution: tuple[int, int]
    samples: int
    max_bounces: int
    adaptive_threshold: float
    denoiser: str
    denoiser_quality: str
    device: str
    threads: int
    persistent_data: bool
    exr_codec: str
    preview: bool
    camera_model: bool = False
    motion_blur: MotionBlur = MotionBlur()
    label_supersample: int = 1
    sky_map_resolution: int = 0
    source: str = ""
    config_hash: str = ""

    @property
    def width(self) -> int:
        return self.resolution[0]

    @property
    def height(self) -> int:
        return self.resolution[1]

    def to_dict(self) -> dict:
        d = dataclasses.asdict(self)
        d.pop("source")
        d.pop("config_hash")
        if not d["camera_model"]:  # off = as every config before the model: same hash, same records
            d.pop("camera_model")
        if not self.motion_blur.enabled:  # off = as every config before the switch: same hash, same records
            d.pop("motion_blur")
        if self.label_supersample == 1:  # 1 = as every config before the option: same hash, same records
            d.pop("label_supersample")
        if not self.sky_map_resolution:  # automatic = as every config before the option: same hash, same records
            d.pop("sky_map_resolution")
        d["resolution"] = list(d["resolution"])
        return d


def resolve_config_path(name_or_path: str | Path) -> Path:
    """A render config path: an existing file, or a preset name from ``render_configs/``."""
    p = Path(name_or_path)
    if p.exists() or p.suffix:
        return p
    return PRESET_DIR / f"{name_or_path}.yaml"


def load_render_config(name_or_path: str | Path) -> RenderConfig:
    """Load and validate a render config file or preset name.

    Raises
    ------
    SpecError
        ``<file>: <field>: <reason>`` for any bad input.
    """
    path = resolve_config_path(name_or_path)
    source = str(name_or_path) if Path(name_or_path).suffix else str(path)
    doc = read_document(path, source)
    if not isinstance(doc, dict):
        raise SpecError(source, "(top level)", f"must be a mapping, got {type(doc).__name__}")
    schema = load_schema("render")
    validate(doc, schema, source)
    full = with_defaults(doc, schema)
    full["resolution"] = tuple(int(v) for v in full["resolution"])
    full["label_supersample"] = int(full["label_supersample"])  # JSON Schema counts 3.0 as an integer
    full["sky_map_resolution"] = int(full["sky_map_resolution"])
    cfg = build(RenderConfig, full)
    cfg = dataclasses.replace(cfg, resolution=tuple(full["resolution"]), source=source)
    return dataclasses.replace(cfg, config_hash=canonical_hash(cfg.to_dict()))
