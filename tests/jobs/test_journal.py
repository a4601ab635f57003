"""The journal (:mod:`generator.jobs.journal`): one line per finished item, read back whatever a kill left."""

from __future__ import annotations

import pytest

from generator.jobs.frameset import FrameSet
from generator.jobs.journal import COMBOS, Journal, Ledger, combo_mask, line, parse_line
from generator.weather import combinations

DAY, NIGHT = ("day", "clear"), ("night", "rain")


def _state(ledger: Ledger) -> list[str]:
    return ledger.records()


def _write_some(j: Journal) -> None:
    j.record_frame(0, [DAY, NIGHT])
    j.record_frame(2, [DAY])
    j.record_stereo("00", 10)
    j.record_town("00", "lidar", FrameSet.span(0, 3), sweeps=16)
    j.record_frame(1, [NIGHT, DAY])
    j.record_town("100", "openlabel", FrameSet.of([5, 6, 9]))
    j.record_dataset("stats", "abc123")
    j.close()


def test_items_are_recorded_once_and_read_back(tmp_path):
    j = Journal(tmp_path)
    _write_some(j)
    assert not j.record_frame(0, [DAY]) and not j.record_stereo("00", 10)  # already there: nothing written
    assert not j.record_town("00", "lidar", FrameSet.span(0, 3), sweeps=16)
    j.close()
    (seg,) = [p for p in j.segments()]
    assert seg.name == "run-000001.log" and len(seg.read_bytes().splitlines()) == 1 + 7  # header + 7 items
    back = Journal(tmp_path).load()
    assert back.frames_done(FrameSet.span(0, 3), combo_mask([DAY, NIGHT])) == FrameSet.span(0, 2)
    assert back.frames_left(FrameSet.span(0, 4), combo_mask([DAY])) == FrameSet.of([3])
    assert back.town_done("00", "lidar", FrameSet.span(0, 3)) == {"sweeps": "16"}
    assert back.town_done("00", "lidar", FrameSet.span(0, 4)) is None  # made for other frames: made again
    assert back.town_done("100", "openlabel", FrameSet.of([5, 6, 9])) == {}
    assert back.stereo == {"00": {10}} and back.dataset == {"stats": "abc123"}
    assert back.n_images(FrameSet.span(0, 3), [DAY, NIGHT]) == 5


def test_every_cut_of_a_segment_reads_back_its_complete_lines(tmp_path):
    """A SIGKILL can stop the writer after any byte: what was written whole is kept, a torn line is not."""
    j = Journal(tmp_path / "full")
    _write_some(j)
    data = j.segments()[0].read_bytes()
    ends = [i + 1 for i, b in enumerate(data) if b == ord("\n")]
    states = {}
    for cut in range(len(data) + 1):
        d = tmp_path / f"cut{cut}"
        (d / "journal").mkdir(parents=True)
        (d / "journal" / "run-000001.log").write_bytes(data[:cut])
        got = Journal(d)
        ledger = got.load()
        whole = sum(e <= cut for e in ends)
        states.setdefault(whole, _state(ledger))
        assert _state(ledger) == states[whole], cut  # exactly the whole lines' items
        assert got.damaged == (0 if cut in (0, *ends) else 1)
    assert states[len(ends)] == _state(Journal(tmp_path / "full").load())


def test_a_damaged_line_is_skipped_not_trusted(tmp_path):
    j = Journal(tmp_path)
    _write_some(j)
    seg = j.segments()[0]
    lines = seg.read_bytes().splitlines(keepends=True)
    lines[1] = lines[1].replace(b"frame 0", b"frame 9")  # the checksum no longer matches
    seg.write_bytes(b"".join(lines))
    back = Journal(tmp_path)
    ledger = back.load()
    assert back.damaged == 1 and not ledger.frame_done(0, combo_mask([DAY])) and not ledger.frame_done(9, 1)
    assert parse_line(line("frame 3 day:clear")) == "frame 3 day:clear" and parse_line(b"frame 3 day:clear\n") is None


def test_compaction_is_the_union_in_a_canonical_order(tmp_path):
    a, b = Journal(tmp_path / "a"), Journal(tmp_path / "b")
    _write_some(a)
    b.record_dataset("stats", "abc123")  # the same items in another order, over two runs
    b.record_town("100", "openlabel", FrameSet.of([5, 6, 9]))
    b.record_frame(1, [DAY])
    b.compact()
    b.record_frame(1, [NIGHT])
    b.record_town("00", "lidar", FrameSet.span(0, 3), sweeps=16)
    for k, c in ((2, [DAY]), (0, [NIGHT, DAY])):
        b.record_frame(k, c)
    b.record_stereo("00", 10)
    b.close()
    assert [p.name for p in b.segments()] == ["merged.log", "run-000001.log"]
    a.compact()
    b.load()
    b.compact()
    assert [p.name for p in b.segments()] == ["merged.log"]
    assert (tmp_path / "a" / "journal" / "merged.log").read_bytes() == (
        tmp_path / "b" / "journal" / "merged.log"
    ).read_bytes()
    text = (tmp_path / "a" / "journal" / "merged.log").read_text()
    assert "frames 0-1 day:clear,night:rain" in text and "frames 2-2 day:clear" in text


def test_a_compaction_killed_before_removing_its_segments_reads_the_same(tmp_path):
    j = Journal(tmp_path)
    _write_some(j)
    before = _state(Journal(tmp_path).load())
    seg = j.segments()[0].read_bytes()
    j.ledger = Journal(tmp_path).load()
    j.compact()
    (tmp_path / "journal" / "run-000001.log").write_bytes(seg)  # as if killed before the removal
    assert _state(Journal(tmp_path).load()) == before


def test_a_million_images_of_bookkeeping(tmp_path):
    """83 334 frames x 12 variants: recorded line by line, read back, compacted to one line, nothing left."""
    frames, combos = FrameSet.span(0, 83_334), combinations()
    j = Journal(tmp_path)
    for k in frames:
        j.record_frame(k, combos)
    j.close()
    ledger = Journal(tmp_path).load()
    assert ledger.n_images(frames, combos) == 1_000_008 == len(frames) * len(combos)
    assert not ledger.frames_left(frames, combo_mask(combos))
    assert ledger.frame_bits.nbytes <= 4 * 2 * 83_334 + 4096  # four bytes a frame
    j2 = Journal(tmp_path)
    j2.ledger = ledger
    j2.compact()
    merged = (tmp_path / "journal" / "merged.log").read_text().splitlines()
    assert len(merged) == 2 and merged[1].startswith("frames 0-83333 day:clear,night:clear,day:fog")


@pytest.mark.parametrize("combo", COMBOS)
def test_every_variant_has_its_bit(combo):
    assert combo_mask([combo]).bit_count() == 1 and combo_mask(COMBOS) == (1 << len(COMBOS)) - 1
