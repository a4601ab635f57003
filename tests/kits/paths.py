"""Where things are, for tests in any folder: the checkout and the shared reference beside it."""

from __future__ import annotations

from pathlib import Path

#: the root of the checkout (holds pyproject.toml, scenes/, generator/)
ROOT = Path(__file__).resolve().parents[2]
#: the shared reference beside the checkout (``../shared`` from the project root); may be absent
SHARED = ROOT.parent / "shared"
