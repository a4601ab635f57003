"""The test town's ``urbangen generate`` reference run, made once per test run and shared by the modules that
read it (:mod:`kits.shared_build`): ``tests/commands/test_generate.py`` (which also remakes it killed and on
Ray, and compares) and ``tests/fusion/test_kitti_stream.py`` (its KITTI stereo stream).

Two frames in two variants at the test preset, two render workers: 4 images, a 9-sweep LiDAR
sequence with a stereo pair at sweep 0. (Three frames in three variants cost the three runs of
``tests/commands/test_generate.py`` ~12 s each for no property more: fog and twelve-image runs are
``tests/commands/test_render.py``'s.)
"""

from __future__ import annotations

from pathlib import Path

from kits.shared_build import SharedBuild

VARIANTS = "day:clear,night:rain"
FRAMES = "2"


def generate_args(root: Path, out: Path, *extra: str) -> list[str]:
    """``urbangen generate`` of the reference into ``out`` (``extra``: more options)."""
    return ["generate", str(root / "scenes/test_town.json"), "--config", "test", "--out", str(out),
            "--frames", FRAMES, "--variants", VARIANTS, *extra]


def reference_run(tmp_path_factory, root: Path) -> SharedBuild:
    """The uninterrupted two-worker run, made when a test first asks for it (read-only)."""
    def build(out: Path) -> None:
        from generator.cli import main

        assert main(["-q", *generate_args(root, out, "--workers", "2")]) == 0

    return SharedBuild(tmp_path_factory, "generate_reference", build)
