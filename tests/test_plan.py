"""Dataset plans: balanced like seed 003 Table II; variants parse; renders per frame."""

from __future__ import annotations

import pytest

from generator.jobs.plan import Plan, make_plan
from generator.jobs.variants import parse_combos, renders_needed
from generator.weather import KINDS, TIMES, combinations, lidar_combination


def test_full_plan_is_balanced():
    plan = make_plan(418)
    counts = plan.counts()
    assert len(counts) == 12 and set(counts.values()) == {418}
    assert sum(counts.values()) == 5016  # seed 003 Table II total
    assert plan.is_balanced()
    assert Plan.from_dict(plan.to_dict()) == plan


def test_twelve_variants_cost_four_renders():
    assert renders_needed(combinations()) == [("day", False), ("day", True), ("night", False), ("night", True)]
    assert renders_needed([("day", "clear"), ("day", "fog")]) == [("day", False)]


def test_parse_combos():
    assert parse_combos("all") == combinations()
    assert parse_combos("clear") == [("day", "clear")]
    assert parse_combos("night:rain_fog, day:wet,night:rain_fog") == [("night", "rain_fog"), ("day", "wet")]
    with pytest.raises(ValueError, match="unknown variant 'dusk:fog'"):
        parse_combos("dusk:fog")


def test_lidar_weather_is_balanced_over_frames():
    seen = [lidar_combination(k) for k in range(24)]
    assert {c: seen.count(c) for c in set(seen)} == {c: 2 for c in combinations()}
    assert set(KINDS) == {k for _, k in seen} and set(TIMES) == {t for t, _ in seen}
