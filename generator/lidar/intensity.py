"""Intensity (remission) models: per-class normal profiles, physical received power, hybrid.

Every model is an :data:`IntensityFn` ``fn(points, rng) -> (n,) float32`` in [0, 1] and
carries a ``description`` dict that goes into ``lidar_meta.json``. ``points`` is a
structured array with at least ``range`` (metres) and ``cos_incidence`` and either

* ``class`` (native id) and ``material`` (material id): urbangen's own scans
  (:data:`generator.lidar.scan.POINT_DTYPE`), or
* ``semantic`` (SemanticKITTI raw id, uint16): imported data (CARLA frames), whose
  reflectivity comes from ``reflectivity.yaml``'s ``class_materials``.

Models
------
``class_normal``
    ``I ~ N(mean_c, std_c)`` clipped to [0, 1], with ``c`` the point's class in a profile
    (:class:`IntensityProfile`): its SemanticKITTI raw id if the profile has it, else its
    unified-11 class (seed 000 Table III is per unified class). Clipping piles the tails
    onto 0 and 1, so a wide class (traffic-sign, std 0.367) has a sample mean and std of
    the *censored* normal, not the profile's.
``physical``
    Normalised received power (see ``reflectivity.yaml``)::

        P = rho * (cos + g_retro * cos^p [retroreflective]) * (R0 / R)^2 * exp(-2 alpha0 R)

    relative to a reflectivity-1 Lambertian target at R0 = 10 m and normal incidence, then
    ``I = clip(P (1 + s_rel N) + s_abs N, 0, 1)``. alpha0 is clear air (0); the LiDAR
    weather multiplies by its own ``exp(-2 alpha R)`` later, so fog is not counted twice.
``hybrid``
    ``I = clip(x_c * w(cos, R), 0, 1)``, ``x_c`` the class-normal draw and ``w`` the
    incidence/range gain of ``reflectivity.yaml`` (1 at cos 0.5 and 15 m).
"""

from __future__ import annotations

import functools
import logging
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np
import yaml

from generator.errors import SpecError, UserError
from generator.labels import class_table
from generator.materials import material_table

log = logging.getLogger(__name__)

IntensityFn = Callable[[np.ndarray, np.random.Generator], np.ndarray]
PROFILE_DIR = Path(__file__).resolve().parent / "profiles"
DEFAULT_PROFILE = "semantickitti_table3"
REFLECTIVITY_FILE = Path(__file__).resolve().parent / "reflectivity.yaml"
#: Label spaces a profile lookup can be indexed by.
LABEL_SPACES = ("semantickitti", "unified11")


# -- profiles -------------------------------------------------------------------------------
@dataclass(frozen=True)
class ClassStats:
    """Remission statistics of one class: mean, standard deviation, number of points (None if unknown)."""

    mean: float
    std: float
    count: int | None = None


@dataclass(frozen=True)
class IntensityProfile:
    """Per-class remission statistics.

    Attributes
    ----------
    name, source : str
        Profile name and where its numbers come from.
    unified : dict of str to ClassStats
        By unified-11 class name (``unlabeled``, ``vehicle``, ...).
    semantickitti : dict of int to ClassStats
        By SemanticKITTI raw id; takes precedence over ``unified`` for that raw id.
    pooled : ClassStats or None
        All points together (fitted profiles): the fallback for classes the data did not have
        when there is no ``unlabeled`` entry.
    file : str
        The file it was read from ('' if built in memory).
    """

    name: str
    source: str
    unified: dict[str, ClassStats] = field(default_factory=dict)
    semantickitti: dict[int, ClassStats] = field(default_factory=dict)
    pooled: ClassStats | None = None
    file: str = ""

    def unified_tables(self) -> tuple[np.ndarray, np.ndarray, list[str]]:
        """(12,) float64 mean and std per unified id, and the class names that fell back.

        A missing class uses the ``unlabeled`` entry, else ``pooled``.

        Raises
        ------
        UserError
            If a unified class is missing and there is neither an ``unlabeled`` nor a ``pooled`` entry.
        """
        names = class_table().unified_names
        mean = np.zeros(max(names) + 1)
        std = np.zeros(max(names) + 1)
        fallback = [names[u] for u in sorted(names) if names[u] not in self.unified]
        spare = self.unified.get("unlabeled", self.pooled)
        if fallback and spare is None:
            raise UserError(f"{self.file or self.name}: unified: no entry for {', '.join(fallback)} "
                            "and no 'unlabeled' or 'pooled' entry to fall back on")
        for u, n in names.items():
            st = self.unified.get(n, spare)
            mean[u], std[u] = st.mean, st.std
        return mean, std, fallback

    def raw_tables(self) -> tuple[np.ndarray, np.ndarray, list[str]]:
        """(K,) float64 mean and std per SemanticKITTI raw id 0..K-1 (raw entry, else its unified class)."""
        table = class_table()
        u_mean, u_std, fallback = self.unified_tables()
        size = max(len(table.sk_to_unified), max(self.semantickitti, default=0) + 1)
        uni = np.zeros(size, np.int64)
        uni[: len(table.sk_to_unified)] = table.sk_to_unified
        mean, std = u_mean[uni], u_std[uni]
        for raw, st in self.semantickitti.items():
            mean[raw], std[raw] = st.mean, st.std
        return mean, std, fallback

    def to_dict(self) -> dict:
        """Plain data in the YAML layout of ``profiles/*.yaml``."""
        def row(st: ClassStats) -> dict:
            return {"mean": float(st.mean), "std": float(st.std), "count": None if st.count is None else int(st.count)}
        out = {"name": self.name, "source": self.source,
               "label_space": "semantickitti" if self.semantickitti else "unified11",
               "unified": {k: row(v) for k, v in self.unified.items()}}
        if self.semantickitti:
            out["semantickitti"] = {int(k): dict(row(v), name=class_table().sk_labels.get(int(k), "unknown"))
                                    for k, v in sorted(self.semantickitti.items())}
        if self.pooled is not None:
            out["pooled"] = row(self.pooled)
        return out


def _stats(value, where: str) -> ClassStats:
    if not isinstance(value, dict) or "mean" not in value or "std" not in value:
        raise UserError(f"{where}: must be a mapping with mean and std")
    try:
        mean, std = float(value["mean"]), float(value["std"])
    except (TypeError, ValueError):
        raise UserError(f"{where}: mean and std must be numbers") from None
    if not (math.isfinite(mean) and math.isfinite(std)) or std < 0:
        raise UserError(f"{where}: needs a finite mean and a finite std >= 0, got mean={mean}, std={std}")
    count = value.get("count")
    if count is not None and (not isinstance(count, int) or count < 0):
        raise UserError(f"{where}: count must be a non-negative integer or null, got {count!r}")
    return ClassStats(mean, std, count)


def parse_profile(doc, source: str) -> IntensityProfile:
    """Validate a profile document (``yaml.safe_load`` output) read from ``source``."""
    if not isinstance(doc, dict):
        raise UserError(f"{source}: an intensity profile must be a YAML mapping")
    known = set(class_table().unified_names.values())
    unified_doc, raw_doc = doc.get("unified") or {}, doc.get("semantickitti") or {}
    if not isinstance(unified_doc, dict) or not isinstance(raw_doc, dict):
        raise UserError(f"{source}: 'unified' and 'semantickitti' must be mappings")
    if not unified_doc and not raw_doc:
        raise UserError(f"{source}: no 'unified' or 'semantickitti' class statistics")
    unified = {}
    for name, v in unified_doc.items():
        if name not in known:
            raise UserError(f"{source}: unified: unknown class {name!r}; known: {', '.join(sorted(known))}")
        unified[name] = _stats(v, f"{source}: unified.{name}")
    raw = {}
    for k, v in raw_doc.items():
        if not isinstance(k, int) or not 0 <= k <= 0xFFFF:
            raise UserError(f"{source}: semantickitti: keys must be raw ids 0..65535, got {k!r}")
        raw[k] = _stats(v, f"{source}: semantickitti.{k}")
    pooled = _stats(doc["pooled"], f"{source}: pooled") if doc.get("pooled") is not None else None
    return IntensityProfile(str(doc.get("name", Path(source).stem)), str(doc.get("source", "")), unified, raw, pooled,
                            source)


def load_profile(path: str | Path, name: str | None = None) -> IntensityProfile:
    """Read a profile YAML (``UserError`` naming the file on any problem); ``name`` replaces the path in records."""
    path = Path(path)
    try:
        doc = yaml.safe_load(path.read_text(encoding="utf-8"))
    except OSError as e:
        raise UserError(f"{path}: cannot read intensity profile: {e.strerror or e}") from None
    except yaml.YAMLError as e:
        raise UserError(f"{path}: not valid YAML: {str(e).splitlines()[0]}") from None
    return parse_profile(doc, name or str(path))


def shipped_profiles() -> list[str]:
    """Names of the profiles in ``generator/lidar/profiles``."""
    return sorted(p.stem for p in PROFILE_DIR.glob("*.yaml"))


def resolve_profile(value: str | None, base: str | Path | None = None) -> IntensityProfile:
    """A shipped profile by name (None = :data:`DEFAULT_PROFILE`) or a file path (relative to ``base``)."""
    value = value or DEFAULT_PROFILE
    if value in shipped_profiles():
        return load_profile(PROFILE_DIR / f"{value}.yaml", f"generator/lidar/profiles/{value}.yaml")
    path = Path(value)
    if not path.is_absolute() and base is not None:
        path = Path(base) / path
    if not path.is_file():
        raise UserError(f"{value}: intensity profile not found (not a file, nor one of {', '.join(shipped_profiles())})")
    return load_profile(path)


# -- per-point inputs -----------------------------------------------------------------------
@functools.cache
def reflectivity_config() -> dict:
    """``reflectivity.yaml`` with ``class_materials`` turned into (K,) reflectivity / retro lookups by raw id."""
    doc = yaml.safe_load(REFLECTIVITY_FILE.read_text(encoding="utf-8"))
    mats = material_table()
    size = max(doc["class_materials"]) + 1
    refl = np.full(size, mats["default"].reflectivity, np.float32)
    retro = np.zeros(size, bool)
    for raw, name in doc["class_materials"].items():
        refl[int(raw)], retro[int(raw)] = mats[name].reflectivity, mats[name].retro
    doc["class_reflectivity"], doc["class_retro"] = refl, retro
    return doc


def semantic_ids(points: np.ndarray) -> np.ndarray:
    """(n,) uint16 SemanticKITTI raw ids: ``points['semantic']`` if present, else from the native ``class``."""
    if "semantic" in points.dtype.names:
        return np.asarray(points["semantic"], np.uint16)
    return class_table().to_semantickitti[points["class"]]


def surface_reflectivity(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(n,) float32 905 nm reflectivity and (n,) bool retroreflective flag of each point's surface.

    From the per-point ``material`` when there is one, else from the class (``class_materials``).
    """
    if "material" in points.dtype.names:
        mats = material_table()
        m = points["material"]
        return mats.reflectivity[m], mats.retro[m]
    cfg = reflectivity_config()
    raw = semantic_ids(points).astype(np.int64)
    raw = np.where(raw < len(cfg["class_reflectivity"]), raw, 0)
    return cfg["class_reflectivity"][raw], cfg["class_retro"][raw]


def received_power(points: np.ndarray, alpha_per_m: float | np.ndarray = 0.0) -> np.ndarray:
    """(n,) float64 normalised received power ``P`` of ``reflectivity.yaml`` (1 = rho 1 at R0, normal, clear).

    Parameters
    ----------
    points : (n,) structured
        Needs ``range`` (metres) and ``cos_incidence``, plus ``material`` or a class field.
    alpha_per_m : float or (n,) float
        Extinction coefficient, 1/m (two-way loss ``exp(-2 alpha R)``).
    """
    p = reflectivity_config()["physical"]
    rho, retro = surface_reflectivity(points)
    cos = np.clip(points["cos_incidence"].astype(np.float64), 0.0, 1.0)
    gain = cos + np.where(retro, p["retro_gain"] * cos ** p["retro_exponent"], 0.0)
    r = points["range"].astype(np.float64)
    spread = (p["reference_range_m"] / np.maximum(r, p["min_range_m"])) ** 2
    return rho * gain * spread * np.exp(-2.0 * np.asarray(alpha_per_m, np.float64) * r)


# -- models ---------------------------------------------------------------------------------
def _class_draw(profile: IntensityProfile, label_space: str):
    if label_space not in LABEL_SPACES:
        raise ValueError(f"label_space must be one of {LABEL_SPACES}, got {label_space!r}")
    mean, std, fallback = profile.raw_tables() if label_space == "semantickitti" else profile.unified_tables()
    if fallback:
        log.info("intensity profile %s has no entry for %s; using its 'unlabeled' (else 'pooled') entry",
                 profile.name, ", ".join(fallback))

    def draw(points: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        ids = semantic_ids(points).astype(np.int64)
        ids = np.where(ids < len(mean), ids, 0)  # ids the label set does not know are unlabeled
        return mean[ids] + std[ids] * rng.standard_normal(len(ids))

    desc = {"profile": profile.name, "profile_file": profile.file, "profile_source": profile.source,
            "label_space": label_space, "fallback": fallback}
    return draw, desc


def class_normal(profile: IntensityProfile, label_space: str = "semantickitti") -> IntensityFn:
    """Seed 000's statistical model: ``clip(N(mean_c, std_c), 0, 1)`` per point of class ``c``.

    Parameters
    ----------
    profile : IntensityProfile
    label_space : {'semantickitti', 'unified11'}
        What the points' ``semantic`` ids are (native points are always SemanticKITTI raw ids).
    """
    draw, desc = _class_draw(profile, label_space)

    def fn(points: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        return np.clip(draw(points, rng), 0.0, 1.0).astype(np.float32)

    fn.description = {"model": "class_normal", **desc, "clip": [0.0, 1.0]}
    return fn


def physical() -> IntensityFn:
    """Received power of the point's surface (``reflectivity.yaml``) with speckle-like noise, clipped to [0, 1]."""
    p = reflectivity_config()["physical"]

    def fn(points: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        power = received_power(points, p["clear_alpha_per_m"])
        noise = rng.standard_normal((2, len(points)))
        out = power * (1.0 + p["noise_relative"] * noise[0]) + p["noise_absolute"] * noise[1]
        return np.clip(out, 0.0, 1.0).astype(np.float32)

    fn.description = {
        "model": "physical",
        "formula": "clip(P * (1 + noise_relative N) + noise_absolute N, 0, 1); P = rho (cos + retro_gain cos^retro_exponent "
                   "[retroreflective]) (R0 / max(R, min_range_m))^2 exp(-2 clear_alpha R)",
        "normalisation": "P = 1 for a reflectivity-1 Lambertian target at R0 and normal incidence in clear air",
        "reflectivity": "generator/materials.yaml at 905 nm (per point material, else class_materials of reflectivity.yaml)",
        **{k: float(v) for k, v in p.items()},
    }
    return fn


def hybrid(profile: IntensityProfile, label_space: str = "semantickitti") -> IntensityFn:
    """Class-normal draw times the incidence/range gain ``w`` of ``reflectivity.yaml``, clipped to [0, 1]."""
    h = reflectivity_config()["hybrid"]
    draw, desc = _class_draw(profile, label_space)
    a = h["incidence_weight"]

    def fn(points: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        cos = np.clip(points["cos_incidence"].astype(np.float64), 0.0, 1.0)
        r = np.maximum(points["range"].astype(np.float64), h["min_range_m"])
        w = ((1 - a) + a * cos) / ((1 - a) + a * h["reference_cos"]) * (h["reference_range_m"] / r) ** h["range_exponent"]
        return np.clip(draw(points, rng) * np.minimum(w, h["max_gain"]), 0.0, 1.0).astype(np.float32)

    fn.description = {"model": "hybrid", **desc,
                      "formula": "clip(N(mean_c, std_c) * min(max_gain, ((1-a) + a cos) / ((1-a) + a reference_cos) "
                                 "* (reference_range_m / max(R, min_range_m))^range_exponent), 0, 1), a = incidence_weight",
                      **{k: float(v) for k, v in h.items()}}
    return fn


def profile_for_spec(spec) -> IntensityProfile:
    """The spec's ``lidar.intensity_profile`` (a shipped name or a path relative to the spec file)."""
    base = Path(spec.source).parent if spec.source else None
    try:
        return resolve_profile(spec.lidar.intensity_profile, base)
    except UserError as e:
        raise SpecError(spec.source or "spec", "lidar.intensity_profile", str(e)) from None
