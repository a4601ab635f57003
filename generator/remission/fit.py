"""Fit a per-class intensity profile from any SemanticKITTI-layout dataset, streaming and vectorised.

Per scan, the per-class count, sum and sum of squares come from three ``np.bincount``
calls in float64, giving the scan's mean and sum of squared deviations
``M2 = sum(x^2) - sum(x) * mean``; scans are then combined with the pairwise update of Chan,
Golub & LeVeque (1979), which is exact. The only cancellation is within one scan
(n ~ 1e5 values in [0, 1]): its error is at most ~n * 1e-16 relative to sum(x^2), i.e.
below 1e-9 in any standard deviation above 0.01 -- the result equals a per-point Welford
loop to far better than 1e-6. Memory is constant
in the number of scans: three arrays of 65536 float64 (one slot per possible raw id).

``std`` is the sample standard deviation (n - 1), as the published KITTI-CARLA converter's
Welford loop computes it (0 for a class with one point).

The accumulators grow to the largest label seen (260 slots for SemanticKITTI raw ids), so
their size does not depend on the number of scans either.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import yaml

from generator import safeload
from generator.atomic import write_text
from generator.errors import UserError
from generator.formats import semantickitti as sk
from generator.labels import class_table
from generator.progress import progress as progress_bar
from generator.remission.class_profiles import LABEL_SPACES, ClassStats, IntensityProfile

log = logging.getLogger(__name__)



@dataclass
class ClassMoments:
    """Per-key count, mean and M2 (sum of squared deviations from the mean).

    Attributes
    ----------
    count : (K,) int64
    mean : (K,) float64
    m2 : (K,) float64
    """

    count: np.ndarray
    mean: np.ndarray
    m2: np.ndarray

    @classmethod
    def empty(cls, k: int = 0) -> ClassMoments:
        return cls(np.zeros(k, np.int64), np.zeros(k), np.zeros(k))

    @classmethod
    def of(cls, keys: np.ndarray, values: np.ndarray, k: int | None = None) -> ClassMoments:
        """Moments of one batch: (n,) non-negative integer ``keys`` (< k; default max + 1) and (n,) ``values``."""
        keys = np.asarray(keys, np.intp)
        x = np.asarray(values, np.float64)
        k = int(keys.max(initial=-1)) + 1 if k is None else k
        n = np.bincount(keys, minlength=k)
        s = np.bincount(keys, weights=x, minlength=k)
        mean = np.divide(s, n, out=np.zeros(k), where=n > 0)
        m2 = np.bincount(keys, weights=x * x, minlength=k) - s * mean  # sum of squared deviations
        return cls(n.astype(np.int64), mean, np.maximum(m2, 0.0))

    def padded(self, k: int) -> ClassMoments:
        """The same moments with ``k`` slots (zeros appended)."""
        extra = k - len(self.count)
        if extra <= 0:
            return self
        return ClassMoments(np.pad(self.count, (0, extra)), np.pad(self.mean, (0, extra)), np.pad(self.m2, (0, extra)))

    def merge(self, other: ClassMoments) -> ClassMoments:
        """Chan et al.'s pairwise combination of two sets of moments (key i of one with key i of the other)."""
        k = max(len(self.count), len(other.count))
        self, other = self.padded(k), other.padded(k)
        n = self.count + other.count
        na, nb = self.count.astype(np.float64), other.count.astype(np.float64)
        delta = other.mean - self.mean
        safe = np.maximum(na + nb, 1.0)
        mean = self.mean + delta * (nb / safe)
        m2 = self.m2 + other.m2 + delta * delta * (na * nb / safe)
        return ClassMoments(n, np.where(n > 0, mean, 0.0), np.where(n > 0, m2, 0.0))

    def grouped(self, groups: np.ndarray, n_groups: int) -> ClassMoments:
        """Merge keys into ``n_groups`` groups; ``groups`` (K,) int gives each key's group."""
        g = np.asarray(groups, np.intp)
        c = self.count.astype(np.float64)
        n = np.bincount(g, weights=c, minlength=n_groups)
        mean = np.divide(np.bincount(g, weights=c * self.mean, minlength=n_groups), n,
                         out=np.zeros(n_groups), where=n > 0)
        d = self.mean - mean[g]
        m2 = np.bincount(g, weights=self.m2 + c * d * d, minlength=n_groups)
        return ClassMoments(np.rint(n).astype(np.int64), mean, m2)

    def std(self) -> np.ndarray:
        """(K,) sample standard deviation (n - 1; 0 where n < 2)."""
        return np.sqrt(np.divide(self.m2, self.count - 1, out=np.zeros(len(self.m2)), where=self.count > 1))


def _sequences(root: Path, sequences: list[str] | None) -> list[str]:
    present = sk.list_sequences(root)
    if sequences is None:
        chosen = [s for s in present if (root / "sequences" / s / "labels").is_dir()]
        if not chosen:
            raise UserError(f"{root}: no sequence with a labels/ folder")
        return chosen
    out = []
    for s in sequences:
        name = sk.sequence_name(s)
        if name not in present:
            raise UserError(
                f"{root / 'sequences' / name}: sequence not found (present: {', '.join(present) or 'none'})"
            )
        if not (root / "sequences" / name / "labels").is_dir():
            raise UserError(f"{root / 'sequences' / name / 'labels'}: missing; cannot fit intensities without labels")
        out.append(name)
    return out


def read_semantic_remission(scan_path: Path, label_path: Path) -> tuple[np.ndarray, np.ndarray]:
    """(n,) uint16 semantic labels (a view of the low halves) and (n,) float32 remission of one scan.

    Raises
    ------
    UserError
        Bad sizes, a label/point count mismatch or non-finite remission (naming the file).
    """
    pts = sk.read_scan(scan_path)  # whole points, every value finite
    labels = safeload.read_array(label_path, "<u4")
    if len(labels) != len(pts):
        raise UserError(f"{label_path}: {len(labels)} labels but {scan_path} has {len(pts)} points")
    return labels.view("<u2")[::2], pts[:, 3]  # little-endian: the low 16 bits first


def accumulate(
    root: str | Path, sequences: list[str] | None = None, progress: bool = True
) -> tuple[ClassMoments, dict]:
    """Stream every labelled scan of the chosen sequences into per-label moments.

    Returns
    -------
    (ClassMoments, dict)
        Moments per 16-bit label value, and a summary (sequences, scans, points).
    """
    root = Path(root)
    names = _sequences(root, sequences)
    seqs = [sk.Sequence(root, s) for s in names]  # opening validates every sequence before the long loop
    total = ClassMoments.empty()
    n_scans = n_points = 0
    bar = progress_bar(total=sum(len(s) for s in seqs), desc="intensity fit", unit="scan", enabled=progress)
    with bar:
        for seq in seqs:
            for i in seq.frames:
                sem, rem = read_semantic_remission(seq.scan_path(i), seq.label_path(i))
                total = total.merge(ClassMoments.of(sem, rem))
                n_scans += 1
                n_points += len(rem)
                bar.update()
    return total, {"sequences": names, "scans": n_scans, "points": n_points}


def profile_from_moments(moments: ClassMoments, label_space: str, name: str, source: str) -> IntensityProfile:
    """An :class:`IntensityProfile` from label moments of ``label_space`` ('semantickitti' or 'unified11').

    Raises
    ------
    UserError
        If unified-11 labels hold ids above 11, or nothing was counted.
    """
    if label_space not in LABEL_SPACES:
        raise UserError(f"--labels must be one of {', '.join(LABEL_SPACES)}, got {label_space!r}")
    table = class_table()
    names = table.unified_names
    present = np.flatnonzero(moments.count)
    if present.size == 0:
        raise UserError(f"{source}: no labelled points to fit")
    std = moments.std()
    stats = {int(k): ClassStats(float(moments.mean[k]), float(std[k]), int(moments.count[k])) for k in present}
    every = moments.grouped(np.zeros(len(moments.count), np.intp), 1)
    pooled = ClassStats(float(every.mean[0]), float(every.std()[0]), int(every.count[0]))
    if label_space == "unified11":
        bad = [int(k) for k in present if k not in names]
        if bad:
            raise UserError(
                f"{source}: labels {bad[:5]} are not unified-11 ids 0..{max(names)} (use --labels semantickitti?)"
            )
        return IntensityProfile(name, source, {names[k]: st for k, st in stats.items()}, {}, pooled)
    unknown = [int(k) for k in present if k not in table.sk_labels]
    if unknown:
        log.warning("raw ids %s are not SemanticKITTI labels; their points count as unlabeled", unknown[:10])
    groups = np.zeros(len(moments.count), np.intp)
    m = min(len(groups), len(table.sk_to_unified))
    groups[:m] = table.sk_to_unified[:m]
    uni = moments.grouped(groups, max(names) + 1)
    ustd = uni.std()
    unified = {names[u]: ClassStats(float(uni.mean[u]), float(ustd[u]), int(uni.count[u]))
               for u in sorted(names) if uni.count[u] > 0}
    return IntensityProfile(name, source, unified, stats, pooled)


def fit_dataset(root: str | Path, sequences: list[str] | None = None, label_space: str = "semantickitti",
                progress: bool = True) -> tuple[IntensityProfile, dict]:
    """Fit the profile of a SemanticKITTI-layout dataset (see :func:`accumulate`)."""
    if label_space not in LABEL_SPACES:
        raise UserError(f"--labels must be one of {', '.join(LABEL_SPACES)}, got {label_space!r}")
    moments, summary = accumulate(root, sequences, progress)
    source = f"urbangen intensity fit of {root} sequences {','.join(summary['sequences'])} ({label_space} labels)"
    return profile_from_moments(moments, label_space, f"fit_{Path(root).name}", source), summary


def format_profile(profile: IntensityProfile, summary: dict | None = None) -> str:
    """The profile as YAML text in the layout of ``profiles/*.yaml``."""
    head = ["# Intensity profile: per-class remission mean, sample standard deviation (n - 1) and point count.",
            "# 'semantickitti' (by raw id) takes precedence over 'unified' (by unified-11 class) when sampling;",
            "# classes absent from the data use 'unlabeled', else 'pooled' (all points together)."]
    if summary:
        head.append(f"# {summary['scans']} scans, {summary['points']} points.")
    return (
        "\n".join(head) + "\n" + yaml.safe_dump(profile.to_dict(), sort_keys=False, default_flow_style=None, width=120)
    )


def write_profile(path: str | Path, profile: IntensityProfile, summary: dict | None = None) -> None:
    """Write :func:`format_profile` atomically."""
    write_text(path, format_profile(profile, summary))
