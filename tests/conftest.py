"""Shared fixtures: a seeded rng, the test and default specs, a cached test-town scene; the
scheduling that keeps a module's shared build on one worker under ``pytest -n 2 --dist loadgroup``."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from kits.paths import ROOT


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(12345)


@pytest.fixture(scope="session")
def root() -> Path:
    return ROOT


@pytest.fixture(scope="session", autouse=True)
def _shared_prototypes(tmp_path_factory):
    """Under pytest-xdist the workers share the asset prototypes they build (:mod:`kits.proto_store`):
    a town's library is built once per run instead of once per worker that builds a town of it."""
    import os

    if os.environ.get("PYTEST_XDIST_WORKER"):
        from kits.proto_store import install

        install(tmp_path_factory.getbasetemp().parent / "prototypes")


def _controller_temp(config) -> Path | None:
    """The run's temporary folder, in the process that controls the run (the only one under plain ``pytest``,
    the one that starts the workers under ``pytest -n 2``); None in a worker."""
    import os

    factory = getattr(config, "_tmp_path_factory", None)
    if factory is None or hasattr(config, "workerinput") or os.environ.get("PYTEST_XDIST_WORKER"):
        return None
    return factory.getbasetemp()


def pytest_terminal_summary(terminalreporter, config):
    """Where the run's shared builds (:mod:`kits.shared_build`) spent their time and made workers wait."""
    temp = _controller_temp(config)
    if temp is None:
        return
    from kits.shared_build import summary

    for line in summary(temp):
        terminalreporter.write_line(line)


def pytest_sessionfinish(session):
    """The controlling process of ``pytest -n 2`` drops the shared prototypes (GBs) once the workers are done."""
    import shutil

    temp = _controller_temp(session.config)
    if temp is not None:
        shutil.rmtree(temp / "prototypes", ignore_errors=True)


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


try:
    from xdist.scheduler import LoadGroupScheduling
except ImportError:  # pytest-xdist is in the test extra; without it the suite runs in one process
    LoadGroupScheduling = None
if LoadGroupScheduling is not None:

    class _SharedBuildScheduling(LoadGroupScheduling):
        """``--dist loadgroup``: the tests of a module that use its module-scoped build run on one
        worker, every other test wherever a worker is free (:mod:`kits.xdist_groups`)."""

        def _split_scope(self, nodeid: str) -> str:
            if nodeid.rfind("@") > nodeid.rfind("]"):       # an xdist_group mark xdist could apply
                return super()._split_scope(nodeid)
            from kits.xdist_groups import scope_of

            return scope_of(nodeid, self.config.rootpath)

    def pytest_xdist_make_scheduler(config, log):
        if config.getvalue("dist") == "loadgroup":
            return _SharedBuildScheduling(config, log)
        return None


# Hypothesis profiles for the property tests: ``dev`` (default, 100 examples), ``ci`` (25
# examples, derandomized; chosen when the ``CI`` environment variable is set) and ``thorough``
# (1000 examples). ``HYPOTHESIS_PROFILE`` picks one by name, e.g.
# ``HYPOTHESIS_PROFILE=thorough pytest tests/test_hostile_specs.py``.
try:
    from hypothesis import HealthCheck
    from hypothesis import settings as _hyp_settings
except ImportError:  # hypothesis is in the test extra; only the property tests need it
    _hyp_settings = None
if _hyp_settings is not None:
    import os as _os

    # No per-example deadline (a CLI run can take a second on a slow machine); the tests bound time themselves.
    _common = {"deadline": None, "suppress_health_check": [HealthCheck.too_slow]}
    _hyp_settings.register_profile("ci", max_examples=25, derandomize=True, database=None, **_common)
    _hyp_settings.register_profile("dev", max_examples=100, **_common)
    _hyp_settings.register_profile("thorough", max_examples=1000, **_common)
    _hyp_settings.load_profile(_os.environ.get("HYPOTHESIS_PROFILE") or ("ci" if _os.environ.get("CI") else "dev"))


# -- detection datasets and their exports (tests/kits/detection_data.py), built once per test run ----------
# (kits.shared_build: by the first pytest-xdist worker that asks; the other waits instead of building its own)
@pytest.fixture(scope="session")
def frozen_detection_dataset(tmp_path_factory, test_spec, test_scene):
    """The cast test town with a ray-cast stereo stream, seed-003 images, box file and OpenLABEL (read-only)."""
    from kits.detection_data import frozen_dataset
    from kits.shared_build import SharedBuild

    def build(out: Path) -> None:
        out.mkdir()
        frozen_dataset(out, test_spec, test_scene)

    return SharedBuild(tmp_path_factory, "frozen_det", build).path()


@pytest.fixture(scope="session")
def traffic_detection_dataset(tmp_path_factory):
    """(dataset, spec file) of a small town with moving traffic, its box file and OpenLABEL (read-only)."""
    from kits.detection_data import traffic_dataset
    from kits.shared_build import SharedBuild

    folder = SharedBuild(tmp_path_factory, "traffic_det", lambda out: traffic_dataset(out / "ds")).path()
    return folder / "ds", folder / "ds_spec.json"


@pytest.fixture(scope="session")
def nuscenes_traffic(traffic_detection_dataset, tmp_path_factory):
    """``urbangen export nuscenes`` of the traffic dataset (read-only)."""
    from generator import cli
    from kits.shared_build import SharedBuild

    root, _ = traffic_detection_dataset

    def build(out: Path) -> None:
        out.mkdir()
        assert cli.main(["export", "nuscenes", str(root), str(out / "nus")]) == 0

    return SharedBuild(tmp_path_factory, "nus_traffic", build).path() / "nus"
