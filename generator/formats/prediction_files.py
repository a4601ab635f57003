"""Finding a model's prediction for each of our images, the way cityscapesScripts finds them.

cityscapesScripts (``evalPixelLevelSemanticLabeling.getPrediction``) walks the results folder
recursively once and, for a ground truth ``<city>_<seq>_<frame>_gtFine_labelIds.png``, takes the one
file whose name matches ``<city>_<seq>_<frame>*.png``; none is "no prediction", two are an error.
:meth:`PredictionFolder.by_stem` does exactly that with the stems of ``urbangen export cityscapes``
(:func:`generator.formats.cityscapes.image_stem`). The KITTI stream's images are matched by their
``image_2`` file name instead (:meth:`PredictionFolder.by_name`: ``000010.png`` anywhere in the folder).
"""

from __future__ import annotations

import fnmatch
import os
from pathlib import Path

from generator.errors import UserError
from generator.safeload import printable


class PredictionFolder:
    """The PNG files of a prediction folder, walked once (as cityscapesScripts does).

    Parameters
    ----------
    root : path-like
        Folder holding the predicted label PNGs, at any depth.

    Raises
    ------
    UserError
        The folder holds no PNG file at all.
    """

    def __init__(self, root: str | Path):
        self.root = Path(root)
        self._walk = [(Path(d), sorted(f for f in files if f.endswith(".png")))
                      for d, _, files in os.walk(self.root)]
        self._walk = [(d, files) for d, files in self._walk if files]
        if not self._walk:
            raise UserError(f"{printable(self.root)}: no .png label maps in this folder")
        self.used: set[Path] = set()

    def _one(self, hits: list[Path], what: str) -> Path | None:
        if len(hits) > 1:
            raise UserError(f"{printable(hits[1])}: a second prediction for {what} (first: {printable(hits[0])}); "
                            "keep one file per image")
        if hits:
            self.used.add(hits[0])
            return hits[0]
        return None

    def by_stem(self, stem: str) -> Path | None:
        """The file named ``<stem>*.png`` (a Cityscapes ``<city>_<seq>_<frame>``), or None."""
        pattern = f"{stem}*.png"
        return self._one([d / f for d, files in self._walk for f in fnmatch.filter(files, pattern)], stem)

    def by_name(self, name: str) -> Path | None:
        """The file named exactly ``name`` (an ``image_2`` file name such as ``000010.png``), or None."""
        return self._one([d / f for d, files in self._walk for f in files if f == name], name)

    def files(self) -> list[Path]:
        """Every PNG of the folder."""
        return [d / f for d, files in self._walk for f in files]

    def unused(self) -> list[Path]:
        """The PNGs no lookup returned (predictions for images this dataset does not have)."""
        return [p for p in self.files() if p not in self.used]
