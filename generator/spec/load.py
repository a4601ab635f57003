"""Read and validate scene specs and render configs.

Each loader reads the file safely (``json`` / ``yaml.safe_load``), validates it against
its packaged JSON Schema, checks cross-field rules, fills defaults and returns frozen
dataclasses. Any problem is one :class:`generator.errors.SpecError`.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
from pathlib import Path

from generator.errors import SpecError
from generator.spec.model import Assets, SceneSpec, build
from generator.spec.validate import check_ranges, load_schema, read_document, validate, with_defaults


def canonical_hash(data: dict) -> str:
    """SHA-256 hex digest of the canonical JSON of ``data`` (sorted keys, no spaces)."""
    return hashlib.sha256(json.dumps(data, sort_keys=True, separators=(",", ":")).encode()).hexdigest()


def parse_spec(document: object, source: str) -> SceneSpec:
    """Validate an already parsed spec document and build the :class:`SceneSpec`."""
    schema = load_schema("scene")
    if not isinstance(document, dict):
        raise SpecError(source, "(top level)", f"must be a JSON object, got {type(document).__name__}")
    validate(document, schema, source)
    full = with_defaults(document, schema)
    check_ranges(full, source)
    check_streets(full, source)
    spec = build(SceneSpec, full)
    return dataclasses.replace(spec, source=source, spec_hash=spec_hash(spec))


def spec_hash(spec: SceneSpec) -> str:
    """The spec's :func:`canonical_hash`; ``town.redraw_every_frames``, ``streets.roundabouts``,
    ``streets.closed_streets``, ``streets.residential_strips``, ``streets.drive_types``,
    ``traffic.vans_per_km``, ``traffic.counts`` and ``assets`` count only when set (``assets``: when not
    the default), so the hash of every spec written before those options is unchanged (resumable datasets
    stay resumable)."""
    d = spec.to_dict()
    if d["town"].get("redraw_every_frames") is None:
        d["town"].pop("redraw_every_frames", None)
    for key in ("roundabouts", "closed_streets"):    # likewise these streets fields while 0
        if d.get("streets") is not None and not d["streets"].get(key):
            d["streets"].pop(key, None)
    if d.get("streets") is not None and list(d["streets"].get("intersection_angle_deg", (90, 90))) == [90, 90]:
        d["streets"].pop("intersection_angle_deg", None)   # and the angle while right
    if d.get("streets") is not None and d["streets"].get("residential_strips", "either") == "either":
        d["streets"].pop("residential_strips", None)       # and the residential strips while drawn per side
    if d.get("streets") is not None and d["streets"].get("drive_types") is None:
        d["streets"].pop("drive_types", None)              # and the drive's street types while drawn
    if not d["traffic"].get("vans_per_km"):             # and the traffic's vans and counts while unused
        d["traffic"].pop("vans_per_km", None)
    if d["traffic"].get("counts") is None:
        d["traffic"].pop("counts", None)
    if d["sensors"]["lidar"].get("returns") is None:        # and the LiDAR return model while the sensor's own
        d["sensors"]["lidar"].pop("returns", None)
    if d.get("assets") == dataclasses.asdict(Assets()):   # and the asset variety while the default
        d.pop("assets", None)
    return canonical_hash(d)


def check_streets(full: dict, source: str) -> None:
    """Cross-field rules of ``streets``: some weight > 0 in each choice, occupancy within [0, 1], and
    street types other than plain only where the town has strips between the lanes and kerbs.

    One-way streets combine with roundabouts and closed streets: the layout keeps a closed street
    and a roundabout's arms two-way (:mod:`generator.layout.network.one_way`)."""
    streets = full.get("streets")
    if streets is None:
        return
    for key in ("types", "districts"):
        if not any(w > 0 for w in streets[key].values()):
            raise SpecError(source, f"streets.{key}", f"needs a weight > 0, got {json.dumps(streets[key])}")
    lo, hi = streets["parking_occupancy"]
    if lo < 0 or hi > 1:
        raise SpecError(source, "streets.parking_occupancy", f"must lie within [0, 1], got {[lo, hi]}")
    lo, hi = streets["intersection_angle_deg"]
    if lo < 60 or hi > 90:
        raise SpecError(source, "streets.intersection_angle_deg", f"must lie within [60, 90] degrees, got {[lo, hi]}")
    varied = sorted({k for k, w in streets["types"].items() if k != "plain" and w > 0}
                    | {k for k in streets.get("drive_types") or () if k != "plain"})
    if varied and full["town"]["parking_strip_width_m"] <= 0:
        # every type but plain fills or turns the strips between the lanes and the kerbs
        # (generator.layout.network.cross_sections); without them the weights would be silently ignored
        raise SpecError(source, "streets.types", f"{', '.join(varied)} need(s) the strips between lanes and kerbs, "
                        "but town.parking_strip_width_m is 0; give the strips a width or use plain only")


def load_spec(path: str | Path) -> SceneSpec:
    """Load a scene spec JSON file.

    Raises
    ------
    SpecError
        ``<file>: <field>: <reason>`` for a missing file, malformed JSON, unknown key,
        wrong type, out-of-range value or inverted range.
    """
    return parse_spec(read_document(path), str(path))
