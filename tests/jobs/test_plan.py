"""Dataset plans: balanced like seed 003 Table II; variants parse; renders per frame."""

from __future__ import annotations

import pytest

from generator.jobs.plan import Plan, make_plan
from generator.jobs.variants import parse_combos, renders_needed
from generator.weather import DEFAULT_TIMES, KINDS, TIMES, combinations, lidar_combination


def test_full_plan_is_balanced():
    plan = make_plan(418)
    counts = plan.counts()
    assert len(counts) == 12 and set(counts.values()) == {418}
    assert sum(counts.values()) == 5016  # seed 003 Table II total
    assert plan.is_balanced()
    assert Plan.from_dict(plan.to_dict()) == plan


def test_twelve_variants_cost_six_renders():
    """Per time of day: sunny and dry (clear), overcast and dry (fog), overcast and wet (the rest)."""
    assert renders_needed(combinations()) == [("day", False, False), ("day", False, True), ("day", True, True),
                                              ("night", False, False), ("night", False, True), ("night", True, True)]
    assert renders_needed([("day", "clear"), ("day", "fog")]) == [("day", False, False), ("day", False, True)]
    assert renders_needed([("night", "rain"), ("dusk", "wet_fog"), ("dusk", "wet")]) == [("dusk", True, True),
                                                                                        ("night", True, True)]


def test_default_plan_is_seed_003s_and_dusk_only_when_asked():
    """Without a times-of-day option the plan is the 12 day/night variants, in the order of before."""
    assert DEFAULT_TIMES == ("day", "night")
    assert combinations() == [(t, k) for k in KINDS for t in ("day", "night")]
    assert make_plan(2).combos == tuple(combinations())
    three = combinations(("night", "dusk", "day"))  # listed in any order: table order
    assert len(three) == 18 and three[:3] == [("day", "clear"), ("dusk", "clear"), ("night", "clear")]
    assert parse_combos("all", ("day", "dusk", "night")) == three
    with pytest.raises(ValueError, match="unknown time of day 'noon'"):
        combinations(("day", "noon"))


def test_parse_combos():
    assert parse_combos("all") == combinations()
    assert parse_combos("clear") == [("day", "clear")]
    assert parse_combos("night:rain_fog, day:wet,night:rain_fog") == [("night", "rain_fog"), ("day", "wet")]
    assert parse_combos("dusk:fog,night:rain") == [("dusk", "fog"), ("night", "rain")]
    with pytest.raises(ValueError, match="unknown variant 'noon:fog'"):
        parse_combos("noon:fog")


def test_lidar_weather_is_balanced_over_frames():
    seen = [lidar_combination(k) for k in range(24)]
    assert {c: seen.count(c) for c in set(seen)} == {c: 2 for c in combinations()}
    assert set(KINDS) == {k for _, k in seen} and set(DEFAULT_TIMES) == {t for t, _ in seen}
    with_dusk = [lidar_combination(k, TIMES) for k in range(18)]
    assert sorted(with_dusk) == sorted(combinations(TIMES))
