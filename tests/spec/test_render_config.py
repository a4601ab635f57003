"""Render config options: validated with one clear message, and the default keeps every older config's hash."""

from __future__ import annotations

import pytest

from generator.errors import SpecError
from generator.spec.render import load_render_config

BASE = "name: r\nresolution: [64, 64]\nsamples: 4\n"


def test_sky_map_resolution_is_validated_and_automatic_keeps_the_old_hash(tmp_path):
    p = tmp_path / "r.yaml"
    p.write_text(BASE)
    plain = load_render_config(p)
    assert plain.sky_map_resolution == 0 and "sky_map_resolution" not in plain.to_dict()
    p.write_text(BASE + "sky_map_resolution: 0\n")
    assert load_render_config(p).config_hash == plain.config_hash
    p.write_text(BASE + "sky_map_resolution: 256.0\n")
    small = load_render_config(p)
    assert type(small.sky_map_resolution) is int and small.sky_map_resolution == 256
    assert small.config_hash != plain.config_hash and small.to_dict()["sky_map_resolution"] == 256
    for bad in ("-1", "8193", "12.5", "'256'", "true", "[256]"):
        p.write_text(BASE + f"sky_map_resolution: {bad}\n")
        with pytest.raises(SpecError, match="sky_map_resolution"):
            load_render_config(p)


def test_the_small_presets_use_a_small_sky_map_and_the_dataset_presets_the_automatic_one():
    assert load_render_config("test").sky_map_resolution == load_render_config("first_look").sky_map_resolution == 256
    assert all(load_render_config(name).sky_map_resolution == 0 for name in ("preview", "paper", "paper_gpu"))
