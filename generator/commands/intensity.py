"""``urbangen intensity fit DATASET [--sequences 00,01] [--labels semantickitti|unified11] -o PROFILE.yaml``.

Fits per-class remission mean and standard deviation from any SemanticKITTI-layout dataset
(streaming, vectorised; see :mod:`generator.remission.fit`) and writes a profile the
``class_normal`` and ``hybrid`` intensity models read (``lidar.intensity_profile`` or
``--intensity-profile``). Also home of the intensity / domain-gap / LiDAR-weather options
that ``lidar`` and ``import-carla`` share.
"""

from __future__ import annotations

import os
from pathlib import Path

from generator.commands.options import Number, path, sequence_list, text_path
from generator.commands.preflight import input_dir, output_file
from generator.errors import UserError
from generator.formats.semantickitti import semantickitti_root
from generator.remission.class_profiles import LABEL_SPACES, resolve_profile
from generator.remission.models import MODEL_NAMES, IntensityFn, intensity_model
from generator.scan_effects.domain_gap import DomainGap, preset

WEATHER_CHOICES = {"auto": None, "on": True, "off": False}


def register(sub) -> None:
    p = sub.add_parser("intensity", help="intensity profiles: fit per-class remission statistics from a dataset",
                       description=__doc__.split("\n\n")[1])
    actions = p.add_subparsers(dest="intensity_command", metavar="ACTION", parser_class=type(p))
    actions.required = True
    f = actions.add_parser("fit", help="fit a per-class intensity profile from a SemanticKITTI-layout dataset")
    f.add_argument("dataset", type=path, help="SemanticKITTI root (sequences/NN/velodyne and labels) or a "
                                                  "dataset folder (lidar/sequences/NN)")
    f.add_argument("--sequences", type=sequence_list, default=None,
                   help="comma-separated sequence numbers (default: every labelled sequence)")
    f.add_argument("--labels", choices=LABEL_SPACES, default="semantickitti",
                   help="label set of the .label files (default semantickitti raw ids)")
    f.add_argument("-o", "--output", required=True, type=path, help="profile YAML to write")
    f.set_defaults(func=run_fit)


def run_fit(args) -> int:
    from generator.remission.fit import fit_dataset, write_profile

    input_dir(args.dataset, what="dataset folder")
    args.dataset = semantickitti_root(args.dataset)  # a dataset folder's lidar/ or a SemanticKITTI root
    output_file(args.output, "-o")
    profile, summary = fit_dataset(args.dataset, args.sequences, args.labels)
    write_profile(args.output, profile, summary)
    print(f"fitted {len(profile.unified)} unified / {len(profile.semantickitti)} raw classes from "
          f"{summary['scans']} scans ({summary['points']} points) -> {args.output}")
    return 0


# -- options shared by lidar and import-carla ------------------------------------------------
def add_processing_args(p, weather: bool = False) -> None:
    """Add ``--intensity``, ``--intensity-profile``, ``--constant-intensity``, the domain-gap options and,
    with ``weather``, ``--lidar-weather``."""
    g = p.add_argument_group("LiDAR post-processing (intensity -> domain gap -> weather)")
    g.add_argument("--intensity", choices=MODEL_NAMES, default=None, help="intensity model (default: the spec's)")
    g.add_argument("--intensity-profile", type=text_path, default=None,
                   help="profile for class_normal/hybrid: a shipped name (semantickitti_table3) or a YAML path")
    g.add_argument("--constant-intensity", type=Number(0, 1), default=None,
                   help="value of the constant model, in [0, 1]")
    g.add_argument("--domain-gap", choices=("off", "seed002"), default=None,
                   help="seed 002 processing: 10%% removal, +-0.05 m jitter, intensity 1.0 (seed002) or none")
    g.add_argument("--dropout", type=Number(0, 1, below=True), default=None,
                   help="domain gap: fraction of points removed, in [0, 1)")
    g.add_argument("--jitter-m", type=Number(0, 1), default=None,
                   help="domain gap: uniform per-axis jitter half-width, m, in [0, 1]")
    g.add_argument("--gap-intensity", type=Number(0, 1, none=True), default=None,
                   help="domain gap: constant intensity in [0, 1], or 'none' to keep the model's")
    if weather:
        g.add_argument("--lidar-weather", choices=tuple(WEATHER_CHOICES), default=None,
                       help="LiDAR weather of each frame (auto: on for generate datasets, off here)")
        g.add_argument("--returns", choices=("ideal", "strongest", "dual"), default=None,
                       help="how beams become points: ideal = every ray's first hit; strongest / dual = physical "
                            "returns (received power, beam divergence, noise) with one or two points per beam "
                            "(default: the spec's, else the sensor's: physical strongest for the HDL-64E)")


def _profile_value(text: str | None) -> str | None:
    if text is None:
        return None
    # a file from the working directory (os.path.isfile never raises), else a shipped name
    return str(Path(text).resolve()) if os.path.isfile(text) else text


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
        parts["constant_intensity"] = None if args.gap_intensity == "none" else args.gap_intensity
    if parts:
        if args.domain_gap == "off":
            raise UserError("--domain-gap off contradicts --dropout/--jitter-m/--gap-intensity")
        start = gap if gap is not None else DomainGap()
        gap = DomainGap(**{**start.to_dict(), **parts})
    return gap


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
    if getattr(args, "returns", None) is not None:
        d["sensors"]["lidar"]["returns"] = args.returns
    return parse_spec(d, spec.source)


def intensity_fn_from_args(args, default: str = "constant") -> IntensityFn:
    """The intensity function the command line asks for, without a spec."""
    profile = resolve_profile(_profile_value(args.intensity_profile)) if args.intensity_profile else None
    value = 0.5 if args.constant_intensity is None else args.constant_intensity  # in [0, 1]: parsed so
    return intensity_model(args.intensity or default, profile, value)


def gap_from_args(args) -> DomainGap | None:
    """The domain gap the command line asks for (None = off)."""
    return _gap_overrides(args, None)
