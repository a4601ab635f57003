"""Shared fixtures: a seeded rng, the test and default specs, a cached test-town scene."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(12345)


@pytest.fixture(scope="session")
def root() -> Path:
    return ROOT


@pytest.fixture(scope="session")
def test_spec():
    from generator.spec import load_spec

    return load_spec(ROOT / "scenes" / "test_town.json")


@pytest.fixture(scope="session")
def default_spec():
    from generator.spec import load_spec

    return load_spec(ROOT / "scenes" / "default_town.json")


@pytest.fixture(scope="session")
def test_scene(test_spec):
    """The test town built once per session (read-only: do not mutate it)."""
    from generator.layout import build_scene

    return build_scene(test_spec)


@pytest.fixture(scope="session")
def default_scene(default_spec):
    """The default town built once per session (read-only: do not mutate it)."""
    from generator.layout import build_scene

    return build_scene(default_spec)
