"""Per-class intensity profiles: mean and std of remission per class, as data.

A profile (``profiles/<name>.yaml`` or a user file) gives ``mean``/``std`` of remission in
[0, 1] per SemanticKITTI raw id or unified-11 class; seed 000 Table III is the shipped
default (``semantickitti_table3``). :mod:`generator.remission.fit` fits one from any
SemanticKITTI-layout dataset; :mod:`generator.remission.models` draws from it.
"""

from __future__ import annotations

import logging
import math
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from generator import safeload
from generator.errors import SpecError, UserError
from generator.labels import class_table

log = logging.getLogger(__name__)

PROFILE_DIR = Path(__file__).resolve().parent / "profiles"
DEFAULT_PROFILE = "semantickitti_table3"
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
    if not all(isinstance(value[k], (int, float)) and not isinstance(value[k], bool) for k in ("mean", "std")):
        raise UserError(f"{where}: mean and std must be numbers")
    mean, std = float(value["mean"]), float(value["std"])
    if not (math.isfinite(mean) and math.isfinite(std)) or std < 0:
        raise UserError(f"{where}: needs a finite mean and a finite std >= 0, got mean={mean}, std={std}")
    count = value.get("count")
    if count is not None and (not isinstance(count, int) or isinstance(count, bool) or count < 0):
        raise UserError(f"{where}: count must be a non-negative integer or null")
    return ClassStats(mean, std, count)


def parse_profile(doc, source: str) -> IntensityProfile:
    """Validate a profile document (:func:`generator.safeload.load_yaml` output) read from ``source``."""
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
            raise UserError(f"{source}: unified.{safeload.printable(name, 64)}: unknown class; "
                            f"known: {', '.join(sorted(known))}")
        unified[name] = _stats(v, f"{source}: unified.{name}")
    raw = {}
    for k, v in raw_doc.items():
        if not isinstance(k, int) or isinstance(k, bool) or not 0 <= k <= 0xFFFF:
            raise UserError(f"{source}: semantickitti.{safeload.printable(k, 64)}: keys must be raw ids 0..65535")
        raw[k] = _stats(v, f"{source}: semantickitti.{k}")
    pooled = _stats(doc["pooled"], f"{source}: pooled") if doc.get("pooled") is not None else None
    name, origin = doc.get("name", Path(source).stem), doc.get("source", "")
    if not isinstance(name, str) or not isinstance(origin, str):
        raise UserError(f"{source}: name and source must be strings")
    return IntensityProfile(name, origin, unified, raw, pooled, source)


def load_profile(path: str | Path, name: str | None = None) -> IntensityProfile:
    """Read a profile YAML through :mod:`generator.safeload` (a regular UTF-8 file within the YAML
    limit, strict YAML, finite numbers); ``UserError`` naming the file on any problem, never
    quoting it. ``name`` replaces the path in records and messages."""
    source = name or str(path)
    doc = safeload.load_yaml(path, source=source, string_keys=False)
    return parse_profile(doc, source)


def shipped_profiles() -> list[str]:
    """Names of the profiles in ``generator/remission/profiles``."""
    return sorted(p.stem for p in PROFILE_DIR.glob("*.yaml"))


def resolve_profile(value: str | None, base: str | Path | None = None) -> IntensityProfile:
    """A shipped profile by name (None = :data:`DEFAULT_PROFILE`) or a file path (relative to ``base``).

    The path is taken as given (a path the user typed on the command line); a path written in
    a spec goes through :func:`profile_for_spec`, which keeps it inside the spec's folder.
    """
    value = value or DEFAULT_PROFILE
    if value in shipped_profiles():
        return load_profile(PROFILE_DIR / f"{value}.yaml", f"generator/remission/profiles/{value}.yaml")
    path = Path(value)
    if not path.is_absolute() and base is not None:
        path = Path(base) / path
    if not os.path.lexists(path):
        raise UserError(f"{safeload.printable(value, 200)}: intensity profile not found "
                        f"(not a file, nor one of {', '.join(shipped_profiles())})")
    return load_profile(path)


def _written_in_spec_file(spec) -> bool:
    """Whether ``spec.lidar.intensity_profile`` is what the spec FILE says.

    A command line option (``--intensity-profile``) is applied by rewriting the spec, so a
    value that differs from the file's came from the user's command line: it is not confined
    to the spec's folder. A spec file that cannot be re-read counts as the source (confined).
    """
    from generator.spec.validate import read_document

    try:
        doc = read_document(spec.source)
    except UserError:
        return True
    lidar = doc.get("lidar") if isinstance(doc, dict) else None
    return not isinstance(lidar, dict) or lidar.get("intensity_profile") == spec.lidar.intensity_profile


def profile_for_spec(spec, command_line: str | None = None) -> IntensityProfile:
    """The spec's ``lidar.intensity_profile``: a shipped name, or a path relative to the spec file
    that must stay inside the spec's folder (no absolute path, no ``..``, no link leading out).

    Parameters
    ----------
    spec : generator.spec.SceneSpec
    command_line : str, optional
        A profile the user named on the command line: used instead, taken as given (not
        confined), relative paths against the working directory.

    Raises
    ------
    SpecError
        ``<spec>: lidar.intensity_profile: <reason>`` for a path leading out of the spec's
        folder or a missing profile; a bad profile file is named itself.
    """
    if command_line is not None:
        return resolve_profile(command_line)
    value = spec.lidar.intensity_profile
    source = spec.source or "spec"
    if value and value not in shipped_profiles() and spec.source and _written_in_spec_file(spec):
        base = Path(spec.source).parent
        path = safeload.confined_path(base, value, source, "lidar.intensity_profile")
        if not os.path.lexists(path):
            raise SpecError(source, "lidar.intensity_profile", f"{safeload.printable(value, 200)}: intensity profile "
                            f"not found (not a file beside the spec, nor one of {', '.join(shipped_profiles())})")
        return load_profile(path, str(base / value))
    base = Path(spec.source).parent if spec.source else None
    try:
        return resolve_profile(value, base)
    except SpecError:
        raise
    except UserError as e:
        raise SpecError(source, "lidar.intensity_profile", str(e)) from None
