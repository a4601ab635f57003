"""Frame 3 of the test town rendered by ``urbangen render`` in all 12 variants at the test preset, made once
per test run and shared (:mod:`kits.shared_build`) by the tests that read those images:
``tests/commands/test_render.py`` (the command's output), ``tests/blender/test_skies.py`` (day, night and
rain skies) and ``tests/postfx/test_camera.py`` (the camera model off). A variant's pixels do not depend
on which other variants the run renders (``test_skies.py`` and ``test_render.py`` check that, against a
second render of two variants, also made once per run).
"""

from __future__ import annotations

import shutil
from pathlib import Path

from kits.shared_build import SharedBuild

FRAME = 3
SECOND_VARIANTS = "day:clear,night:clear"   #: the variants of :func:`second_render`


def render_args(root: Path, out: Path, variants: str, config: str = "test") -> list[str]:
    """``urbangen -q render`` of frame :data:`FRAME` of the test town into ``out``."""
    return ["-q", "render", str(root / "scenes/test_town.json"), "--config", config, "--out", str(out),
            "--frames", "1", "--first", str(FRAME), "--variants", variants]


def all_variants(tmp_path_factory, root: Path) -> SharedBuild:
    """The render of every variant (a dataset folder; its images are in ``image_dir(folder, FRAME)``)."""
    def build(out: Path) -> None:
        from generator.cli import main

        assert main(render_args(root, out, "all")) == 0

    return SharedBuild(tmp_path_factory, "render_frame3_all", build)


def second_render(tmp_path_factory, root: Path) -> SharedBuild:
    """A second render of day:clear and night:clear, with nothing shared with :func:`all_variants` but the
    inputs: the same-seed-same-image tests of ``tests/commands/test_render.py`` (masks and depth) and
    ``tests/blender/test_skies.py`` (RGB) compare it with the first (each rendered its own before)."""
    def build(out: Path) -> None:
        from generator.cli import main

        assert main(render_args(root, out, SECOND_VARIANTS)) == 0

    return SharedBuild(tmp_path_factory, "render_frame3_again", build)


def copy_images(src: Path, dst: Path, names) -> None:
    """Copy the files of the images ``names`` (stems) from images folder ``src`` into ``dst``."""
    dst.mkdir(parents=True, exist_ok=True)
    for name in names:
        for p in src.glob(f"{name}*"):
            shutil.copy2(p, dst / p.name)
