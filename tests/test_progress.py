"""Long jobs tell a log where they are when nobody watches a terminal."""

from __future__ import annotations

import logging

from generator.progress import LogProgress, progress


def test_log_progress_lines_say_done_total_rate_and_eta(caplog):
    caplog.set_level(logging.INFO, logger="urbangen.progress")
    bar = LogProgress(total=10, desc="render", unit="frame", period_s=0.0)
    bar.update(4)
    bar.close()
    lines = [r.getMessage() for r in caplog.records]
    assert lines[0].startswith("render: 4/10 frame (40%)") and "frame/s" in lines[0] and "ETA" in lines[0]
    assert lines[-1].endswith("(done)") and len(lines) == 2


def test_without_a_terminal_progress_logs_instead_of_drawing(caplog, monkeypatch):
    caplog.set_level(logging.INFO, logger="urbangen.progress")
    import io
    import sys
    monkeypatch.setattr(sys, "stderr", io.StringIO())  # not a TTY
    monkeypatch.setattr("generator.progress.PERIOD_S", 0.0)
    items = list(progress(range(3), desc="scan", unit="scan"))
    assert items == [0, 1, 2]
    assert any("scan: 3/3 scan (100%)" in r.getMessage() for r in caplog.records)
    assert sys.stderr.getvalue() == ""  # no bar characters in a log file


def test_a_short_job_logs_nothing_and_a_failed_one_does_not_say_done(caplog):
    """The result (or the error) is the last line a user reads, not a progress line."""
    caplog.set_level(logging.INFO, logger="urbangen.progress")
    with LogProgress(total=3, desc="verify", unit="image") as bar:
        bar.update(3)
    assert not caplog.records
    try:
        with LogProgress(total=3, desc="verify", unit="image", period_s=0.0) as bar:
            bar.update(1)
            raise ValueError("bad EXR")
    except ValueError:
        pass
    lines = [r.getMessage() for r in caplog.records]
    assert lines and not any("(done)" in m for m in lines)


def test_help_texts_have_no_rest_markup(capsys):
    from generator.cli import build_parser
    parser = build_parser()
    sub = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
    for name, p in sub.choices.items():
        text = p.format_help()
        assert "``" not in text and ":func:" not in text and ":mod:" not in text, name
