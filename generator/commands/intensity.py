"""``urbangen intensity fit DATASET [--sequences 00,01] [--labels semantickitti|unified11] -o PROFILE.yaml``.

Fits per-class remission mean and standard deviation from any SemanticKITTI-layout dataset
(streaming, vectorised; see :mod:`generator.remission.fit`) and writes a profile the
``class_normal`` and ``hybrid`` intensity models read (``lidar.intensity_profile`` or
``--intensity-profile``). Also home of the intensity / domain-gap / LiDAR-weather options
that ``lidar`` and ``import-carla`` share.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from generator.errors import UserError
from generator.scan_effects.domain_gap import DomainGap, preset
from generator.remission.class_profiles import LABEL_SPACES, resolve_profile
from generator.remission.models import MODEL_NAMES, IntensityFn, intensity_model

WEATHER_CHOICES = {"auto": None, "on": True, "off": False}


def register(sub) -> None:
    p = sub.add_parser("intensity", help="intensity profiles: fit per-class remission statistics from a dataset",
                       description=__doc__.split("\n\n")[1])
    actions = p.add_subparsers(dest="intensity_command", metavar="ACTION", parser_class=type(p))
    actions.required = True
    f = actions.add_parser("fit", help="fit a per-class intensity profile from a SemanticKITTI-layout dataset")
    f.add_argument("dataset", type=Path, help="dataset root (holds sequences/NN/velodyne and labels)")
    f.add_argument("--sequences", default=None, help="comma-separated sequence numbers (default: every labelled sequence)")
    f.add_argument("--labels", choices=LABEL_SPACES, default="semantickitti",
                   help="label set of the .label files (default semantickitti raw ids)")
    f.add_argument("-o", "--output", required=True, type=Path, help="profile YAML to write")
    f.set_defaults(func=run_fit)


def parse_sequences(text: str | None) -> list[str] | None:
    """``'00,01'`` -> ``['00', '01']`` (None stays None)."""
    if text is None:
        return None
    items = [s.strip() for s in text.split(",") if s.strip()]
    if not items:
        raise UserError(f"--sequences: expected numbers like 00,01, got {text!r}")
    return items


def run_fit(args) -> int:
    from generator.remission.fit import fit_dataset, write_profile

    if not args.dataset.is_dir():
        raise UserError(f"{args.dataset}: dataset folder not found")
    if args.output.exists() and args.output.is_dir():
        raise UserError(f"-o: {args.output} is a folder")
    profile, summary = fit_dataset(args.dataset, parse_sequences(args.sequences), args.labels)
    write_profile(args.output, profile, summary)
    print(f"fitted {len(profile.unified)} unified / {len(profile.semantickitti)} raw classes from "
          f"{summary['scans']} scans ({summary['points']} points) -> {args.output}")
    return 0


# -- options shared by lidar and import-carla ------------------------------------------------
def _fraction(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    return v


def add_processing_args(p, weather: bool = False) -> None:
    """Add ``--intensity``, ``--intensity-profile``, ``--constant-intensity``, the domain-gap options and,
    with ``weather``, ``--lidar-weather``."""
    g = p.add_argument_group("LiDAR post-processing (intensity -> domain gap -> weather)")
    g.add_argument("--intensity", choices=MODEL_NAMES, default=None, help="intensity model (default: the spec's)")
    g.add_argument("--intensity-profile", default=None,
                   help="profile for class_normal/hybrid: a shipped name (semantickitti_table3) or a YAML path")
    g.add_argument("--constant-intensity", type=_fraction, default=None, help="value of the constant model")
    g.add_argument("--domain-gap", choices=("off", "seed002"), default=None,
                   help="seed 002 processing: 10%% removal, +-0.05 m jitter, intensity 1.0 (seed002) or none")
    g.add_argument("--dropout", type=_fraction, default=None, help="domain gap: fraction of points removed")
    g.add_argument("--jitter-m", type=_fraction, default=None, help="domain gap: uniform per-axis jitter half-width, m")
    g.add_argument("--gap-intensity", default=None, help="domain gap: constant intensity, or 'none' to keep the model's")
    if weather:
        g.add_argument("--lidar-weather", choices=tuple(WEATHER_CHOICES), default=None,
                       help="LiDAR weather of each frame (auto: on for generate datasets, off here)")


def _profile_value(text: str | None) -> str | None:
    if text is None:
        return None
    path = Path(text)
    return str(path.resolve()) if path.is_file() else text  # a file from the working directory, else a shipped name


def _gap_overrides(args, base: DomainGap | None) -> DomainGap | None:
    gap = base
    if args.domain_gap is not None:
        gap = preset("seed002") if args.domain_gap == "seed002" else None
    parts = {}
    if args.dropout is not None:
        parts["dropout"] = args.dropout
    if args.jitter_m is not None:
        parts["jitter_m"] = args.jitter_m
    if args.gap_intensity is not None:
        parts["constant_intensity"] = None if args.gap_intensity.lower() == "none" else _number(args.gap_intensity)
    if parts:
        if args.domain_gap == "off":
            raise UserError("--domain-gap off contradicts --dropout/--jitter-m/--gap-intensity")
        start = gap if gap is not None else DomainGap()
        gap = DomainGap(**{**start.to_dict(), **parts})
    return gap


def _number(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise UserError(f"--gap-intensity: expected a number in [0, 1] or 'none', got {text!r}") from None


def spec_with_processing_args(spec, args):
    """The spec with the command line's post-processing options applied (re-validated, new spec hash)."""
    from generator.spec.load import parse_spec

    d = spec.to_dict()
    lidar = d["lidar"]
    if args.intensity is not None:
        lidar["intensity_model"] = args.intensity
    if args.intensity_profile is not None:
        lidar["intensity_profile"] = _profile_value(args.intensity_profile)
    if args.constant_intensity is not None:
        lidar["constant_intensity"] = args.constant_intensity
    g = lidar["domain_gap"]
    base = DomainGap(g["dropout"], g["jitter_m"], g["constant_intensity"]) if g["enabled"] else None
    gap = _gap_overrides(args, base)
    lidar["domain_gap"] = dict(g, enabled=gap is not None, **(gap.to_dict() if gap else {}))
    if getattr(args, "lidar_weather", None) is not None:
        lidar["weather"]["enabled"] = WEATHER_CHOICES[args.lidar_weather]
    return parse_spec(d, spec.source)


def intensity_fn_from_args(args, default: str = "constant") -> IntensityFn:
    """The intensity function the command line asks for, without a spec."""
    profile = resolve_profile(_profile_value(args.intensity_profile)) if args.intensity_profile else None
    value = 0.5 if args.constant_intensity is None else args.constant_intensity
    if not 0.0 <= value <= 1.0:
        raise UserError(f"--constant-intensity: must be in [0, 1], got {value}")
    return intensity_model(args.intensity or default, profile, value)


def gap_from_args(args) -> DomainGap | None:
    """The domain gap the command line asks for (None = off)."""
    return _gap_overrides(args, None)
