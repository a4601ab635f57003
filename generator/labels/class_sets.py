"""Class sets of image predictions and of their evaluation: merges of the class table, as data.

A segmentation model labels pixels with ids of ITS label set (Cityscapes label ids, train ids, urbangen's
native ids, or anything a user describes in a YAML file). Scoring its labels against urbangen's ground
truth needs both in one set. Every set here is a *merge* of a base set -- ``native`` (the class table,
``classes.yaml``) or ``cityscapes`` (the 34 label ids, ``cityscapes.yaml``, itself the merge of native
classes given by the class table's ``cityscapes`` column) -- so ground truth, which is native, maps into
any set, and a prediction maps into another set exactly when that set does not split any of its classes
(:func:`translate`).

=======================  ============  ===================================================================
name                     base          classes
=======================  ============  ===================================================================
``native``               native        the class table (ignored: 0 unlabeled)
``cityscapes``           cityscapes    the 34 label ids (ignored: the 15 without a train id, as
                                       cityscapesScripts evaluates)
``cityscapes_trainids``  cityscapes    the 19 train ids 0..18 and 255 (ignored), from ``cityscapes.yaml``
``seed001``              cityscapes    seed 001's 34 -> 8 merge (``seed001.yaml``; Cityscapes' categories)
``unified11``            native        seed 000's 11 classes (:mod:`generator.labels.sets`)
``semantickitti``        native        SemanticKITTI's 19 learning classes (:mod:`generator.labels.sets`)
=======================  ============  ===================================================================

The YAML form (``seed001.yaml`` documents it in its header) is what a user writes for another model.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from generator.errors import SpecError
from generator.labels.cityscapes import cityscapes_labels
from generator.labels.registry import DATA_DIR, class_table
from generator.labels.sets import label_sets
from generator.safeload import load_yaml, printable

BASES = ("native", "cityscapes")
#: Largest id a set may use (a label PNG holds up to 16 bits).
MAX_ID = (1 << 16) - 1
#: The built-in sets, in the order help texts list them.
BUILTIN = ("cityscapes", "cityscapes_trainids", "native", "seed001", "unified11", "semantickitti")


@dataclass(frozen=True, eq=False)
class ClassSet:
    """One label set as a merge of its base set.

    Attributes
    ----------
    name : str
    source : str
        Where it was defined (a file, or ``built-in``).
    base : {"native", "cityscapes"}
    names : dict of int -> str
        Id -> class name (ids may be sparse: 255).
    ignore : tuple of int
        Ids not scored as ground truth; ``ignore[0]`` is where unlisted base ids and predictions
        that another set cannot express go.
    from_base : (n_base,) int64
        Id in this set of every base id.
    """

    name: str
    source: str
    base: str
    names: dict
    ignore: tuple
    from_base: np.ndarray

    @property
    def size(self) -> int:
        """Confusion-matrix side: largest id + 1."""
        return max(self.names) + 1

    @functools.cached_property
    def from_native(self) -> np.ndarray:
        """(n_native,) int64: id in this set of every native class."""
        if self.base == "native":
            return self.from_base
        return self.from_base[class_table().to_cityscapes.astype(np.int64)]

    @functools.cached_property
    def known(self) -> np.ndarray:
        """(65536,) bool: which pixel values are ids of this set."""
        out = np.zeros(MAX_ID + 1, bool)
        out[list(self.names)] = True
        return out

    def class_names(self) -> list[str]:
        """Name per id ``0 .. size - 1`` (``""`` for unused ids)."""
        return [self.names.get(i, "") for i in range(self.size)]


# -- the base sets ---------------------------------------------------------------------------------------
def cityscapes_table() -> dict:
    """``cityscapes.yaml`` (:func:`generator.labels.cityscapes.cityscapes_labels`): ``names`` (34,) list,
    ``train`` (34,) int64, ``semantickitti`` (34,) uint16."""
    cs = cityscapes_labels()
    return {"names": cs.names, "train": cs.train_ids.astype(np.int64), "semantickitti": cs.semantickitti}


def base_names(base: str) -> list[str]:
    """Class names of a base set, by id."""
    return list(class_table().names) if base == "native" else cityscapes_table()["names"]


def _base_id(base: str, value, source: str, field: str) -> int:
    names = base_names(base)
    if isinstance(value, bool) or not isinstance(value, (int, str)):
        raise SpecError(source, field, f"must be a {base} class id or name")
    if isinstance(value, int):
        if not 0 <= value < len(names):
            raise SpecError(source, field, f"{value} is not a {base} class id (0..{len(names) - 1})")
        return value
    if value not in names:
        raise SpecError(source, field, f"{printable(value, 60)!r} is not a {base} class name")
    return names.index(value)


# -- building sets -----------------------------------------------------------------------------------------
def parse_class_set(doc: object, source: str) -> ClassSet:
    """A :class:`ClassSet` from a parsed YAML document (format: the header of ``seed001.yaml``).

    Raises
    ------
    SpecError
        ``<file>: <field>: <reason>``: a missing or mistyped field, an unknown base class, a base
        class in two classes, an id outside 0..65535, an ``ignore`` id that is no class, or a set
        that maps to nothing (no class outside ``ignore`` has a member).
    """
    if not isinstance(doc, dict):
        raise SpecError(source, "(top level)", "must be a mapping with base, ignore and classes")
    unknown = sorted(set(doc) - {"name", "base", "ignore", "classes", "description"}, key=str)
    if unknown:
        raise SpecError(source, printable(unknown[0], 40), "unknown field (expected name, base, ignore, classes)")
    base = doc.get("base")
    if base not in BASES:
        raise SpecError(source, "base", f"must be one of {', '.join(BASES)}")
    classes = doc.get("classes")
    if not isinstance(classes, dict) or not classes:
        raise SpecError(source, "classes", "must be a non-empty mapping id -> {name, members}")
    n_base = len(base_names(base))
    owner = np.full(n_base, -1, np.int64)
    names: dict[int, str] = {}
    for cid, row in classes.items():
        field = f"classes.{printable(cid, 20)}"
        if isinstance(cid, bool) or not isinstance(cid, int) or not 0 <= cid <= MAX_ID:
            raise SpecError(source, field, f"class ids must be integers in 0..{MAX_ID}")
        if not (isinstance(row, dict) and isinstance(row.get("name"), str)
                and isinstance(row.get("members", []), list)):
            raise SpecError(source, field, "must be {name: <text>, members: [<base ids or names>]}")
        names[cid] = row["name"]
        for j, m in enumerate(row.get("members", [])):
            b = _base_id(base, m, source, f"{field}.members[{j}]")
            if owner[b] >= 0:
                raise SpecError(source, f"{field}.members[{j}]", f"{base} class {base_names(base)[b]!r} is already "
                                f"in class {int(owner[b])}")
            owner[b] = cid
    ignore = doc.get("ignore")
    if not isinstance(ignore, list) or not ignore or any(isinstance(i, bool) or i not in names for i in ignore):
        raise SpecError(source, "ignore", "must list at least one of the classes' ids (the unscored, void class)")
    if not np.isin(owner, [i for i in names if i not in ignore]).any():
        raise SpecError(source, "classes", "maps to nothing: no class outside `ignore` has a member")
    owner[owner < 0] = ignore[0]
    name = doc.get("name", Path(source).stem)
    if not isinstance(name, str) or not name:
        raise SpecError(source, "name", "must be a non-empty text")
    return ClassSet(name, source, base, names, tuple(int(i) for i in ignore), owner)


def _derived(name: str, base: str, names: dict, ignore, from_base) -> ClassSet:
    return ClassSet(name, "built-in", base, dict(names), tuple(ignore), np.asarray(from_base, np.int64))


@functools.cache
def builtin_sets() -> dict[str, ClassSet]:
    """The built-in sets by name (see the module table)."""
    t, cs = class_table(), cityscapes_table()
    n_cs = len(cs["names"])
    out = {
        "native": _derived("native", "native", dict(enumerate(t.names)), (0,), np.arange(len(t))),
        "cityscapes": _derived("cityscapes", "cityscapes", dict(enumerate(cs["names"])),
                               [i for i in range(n_cs) if cs["train"][i] == 255], np.arange(n_cs)),
    }
    train = {int(cs["train"][i]): cs["names"][i] for i in range(n_cs) if cs["train"][i] != 255}
    out["cityscapes_trainids"] = _derived("cityscapes_trainids", "cityscapes", {**train, 255: "void"}, (255,),
                                          cs["train"])
    out["seed001"] = parse_class_set(load_yaml(DATA_DIR / "seed001.yaml", string_keys=False),
                                     "generator/labels/seed001.yaml")
    for name in ("unified11", "semantickitti"):
        ls = label_sets()[name]
        out[name] = _derived(name, "native", dict(enumerate(ls.names)), (0,), ls.from_native)
    return {k: out[k] for k in BUILTIN}


def load_class_set(arg: str | Path, field: str = "--label-set") -> ClassSet:
    """A built-in set by name, or a label-set YAML file.

    Raises
    ------
    SpecError
        Neither a built-in name nor a readable, valid YAML file (one line naming file and field).
    """
    text = str(arg)
    if text in BUILTIN:
        return builtin_sets()[text]
    if not text.endswith((".yaml", ".yml")):
        raise SpecError(field, "", f"{printable(text, 80)!r} is neither a label set ({', '.join(BUILTIN)}) "
                                   "nor a .yaml file")
    return parse_class_set(load_yaml(text, field=field, string_keys=False), text)


# -- between sets ------------------------------------------------------------------------------------------
def _native_members(s: ClassSet) -> dict[int, np.ndarray]:
    return {cid: np.flatnonzero(s.from_native == cid) for cid in s.names}


def translate(pred: ClassSet, target: ClassSet) -> np.ndarray | None:
    """(pred.size,) int64 id in ``target`` of every id of ``pred``; None when ``target`` splits a class of ``pred``.

    A class of ``pred`` goes to the one scored ``target`` class its base members fall into (compared in
    the common base: the shared one, else native); where they fall into several, members in ignored
    ``target`` classes do not count, as such ground truth is never scored (a Cityscapes building is a
    native building or shelter, and a shelter is unlabeled in unified11: predicted building is unified11's
    building). A class whose members
    reach no scored ``target`` class (a Cityscapes bridge: no native class is one) goes to
    ``target.ignore[0]`` -- predicted, it is a miss. A class that spans several scored ``target`` classes
    makes the sets incompatible, except an ignored (void) class of ``pred``, whose pixels say "no class"
    and go to ``target.ignore[0]``.
    """
    out = np.full(pred.size, target.ignore[0], np.int64)
    if pred.base == target.base:
        members = {cid: np.flatnonzero(pred.from_base == cid) for cid in pred.names}
        lut = target.from_base
    else:
        members, lut = _native_members(pred), target.from_native
    for cid, m in members.items():
        hit = np.unique(lut[m])
        if len(hit) > 1:
            hit = np.setdiff1d(hit, target.ignore)
        if len(hit) == 1:
            out[cid] = hit[0]
        elif len(hit) > 1 and cid not in pred.ignore:
            return None
    return out


def compatible_sets(pred: ClassSet) -> dict[str, np.ndarray]:
    """Built-in sets a prediction in ``pred`` can be scored in: name -> :func:`translate` table."""
    out = {}
    for name, target in builtin_sets().items():
        if name == "cityscapes_trainids":
            continue  # the same 19 classes as "cityscapes", which reports them under their label ids
        lut = translate(pred, target)
        if lut is not None:
            out[name] = lut
    return out


def semantickitti_raw(pred: ClassSet) -> np.ndarray:
    """(pred.size,) uint16 SemanticKITTI raw id a point predicted each id of ``pred`` gets in a .label file.

    Native-based sets: the class table's id of the class's first native member; Cityscapes-based sets:
    ``cityscapes.yaml``'s canonical id of the first Cityscapes member (lossy where Cityscapes merges;
    see that file). Ignored and empty classes: 0.
    """
    t = class_table()
    out = np.zeros(pred.size, np.uint16)
    table = t.to_semantickitti if pred.base == "native" else cityscapes_table()["semantickitti"]
    for cid in pred.names:
        m = np.flatnonzero(pred.from_base == cid)
        if cid not in pred.ignore and len(m):
            out[cid] = table[m[0]]
    return out
