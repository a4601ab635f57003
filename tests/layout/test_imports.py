"""Importing the layout stays cheap: trimesh, scipy.spatial and numba load when a town is built.

Every process that imports the layout (test workers, Blender workers, the CLI) would otherwise pay
~1 s of imports before it does anything.
"""

from __future__ import annotations

import os
import subprocess
import sys

from kits.paths import ROOT

HEAVY = ("trimesh", "scipy.spatial", "numba")


def test_layout_import_leaves_heavy_modules_unloaded():
    code = f"import sys, generator.layout; print(','.join(m for m in {HEAVY!r} if m in sys.modules))"
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=env, capture_output=True, text=True,
                         check=True).stdout.strip()
    assert out == ""
