"""Scene specs and render configs: dataclasses, JSON Schemas, safe loading with clear errors."""

from generator.spec.load import canonical_hash, load_spec, parse_spec
from generator.spec.model import SceneSpec

__all__ = ["SceneSpec", "canonical_hash", "load_spec", "parse_spec"]
