"""Command-line values, parsed strictly at the door (argparse ``type=`` helpers).

Every numeric option of every command is parsed here: plain ASCII decimal digits only
(no ``nan``/``inf``, no ``1_000``, no ``0x10``, no other scripts' digits, no surrounding
spaces), a finite value, inside the option's range. A bad value ends in argparse's usual
path, which :class:`generator.cli.OneLineParser` turns into one line naming the option::

    urbangen lidar: --frames: must be an integer in 1..100000, got 'nan'

Values are echoed escaped and shortened (:func:`generator.safeload.printable`), so a
control character or a 10 000-character argument still gives one short line. Paths get a
first check here too (not empty, no NUL, not absurdly long); whether they exist and what
they are is :mod:`generator.commands.preflight`'s business.
"""

from __future__ import annotations

import argparse
import math
import re
from pathlib import Path

from generator.safeload import printable

_INT = re.compile(r"[+-]?[0-9]{1,30}")
_FLOAT = re.compile(r"[+-]?(?:[0-9]{1,400}(?:\.[0-9]{0,400})?|\.[0-9]{1,400})(?:[eE][+-]?[0-9]{1,5})?")
#: Longest path accepted on the command line (Linux PATH_MAX).
MAX_PATH_CHARS = 4096
#: Longest comma-separated list (frames, sequences) accepted.
MAX_LIST_ITEMS = 10_000


def shown(text: str) -> str:
    """``text`` quoted for a message: escaped, at most 40 characters."""
    return "'" + printable(text, 40) + "'"


def _range(lo: float | None, hi: float | None, integer: bool) -> str:
    fmt = (lambda v: f"{v:d}") if integer else (lambda v: f"{v:g}")
    if lo is not None and hi is not None:
        return f" in {fmt(lo)}..{fmt(hi)}" if integer else f" in [{fmt(lo)}, {fmt(hi)}]"
    if lo is not None:
        return f" >= {fmt(lo)}"
    return f" <= {fmt(hi)}" if hi is not None else ""


class Integer:
    """``type=Integer(1, 100)``: a decimal integer in ``lo..hi`` (either bound may be None)."""

    kind = "integer"  # every helper here says what it parses (the tests find every option by it)

    def __init__(self, lo: int | None = None, hi: int | None = None):
        self.lo, self.hi = lo, hi
        self.__name__ = "integer"  # argparse names the type in some messages

    @property
    def expected(self) -> str:
        return "an integer" + _range(self.lo, self.hi, True)

    def __call__(self, text: str) -> int:
        if not _INT.fullmatch(text):
            raise argparse.ArgumentTypeError(f"must be {self.expected}, got {shown(text)}")
        value = int(text)
        if (self.lo is not None and value < self.lo) or (self.hi is not None and value > self.hi):
            raise argparse.ArgumentTypeError(f"must be {self.expected}, got {shown(text)}")
        return value


class Number:
    """``type=Number(0, 1)``: a finite decimal number in ``[lo, hi]``; ``above``/``below`` make a bound exclusive.

    ``none`` also accepts the word ``none`` (any case), returned as the string ``"none"``.
    """

    kind = "number"

    def __init__(self, lo: float | None = None, hi: float | None = None, above: bool = False, below: bool = False,
                 none: bool = False):
        self.lo, self.hi, self.above, self.below, self.none = lo, hi, above, below, none
        self.__name__ = "number"

    @property
    def expected(self) -> str:
        if self.lo is not None and self.hi is not None:
            text = f"a number in {'(' if self.above else '['}{self.lo:g}, {self.hi:g}{')' if self.below else ']'}"
        elif self.lo is not None:
            text = f"a number {'>' if self.above else '>='} {self.lo:g}"
        elif self.hi is not None:
            text = f"a number {'<' if self.below else '<='} {self.hi:g}"
        else:
            text = "a number"
        return text + (" or 'none'" if self.none else "")

    def __call__(self, text: str) -> float | str:
        if self.none and text.lower() == "none":
            return "none"
        if not _FLOAT.fullmatch(text):
            raise argparse.ArgumentTypeError(f"must be {self.expected}, got {shown(text)}")
        value = float(text)
        if not math.isfinite(value):
            raise argparse.ArgumentTypeError(f"must be a finite number, got {shown(text)}")
        low = self.lo is not None and (value <= self.lo if self.above else value < self.lo)
        high = self.hi is not None and (value >= self.hi if self.below else value > self.hi)
        if low or high:
            raise argparse.ArgumentTypeError(f"must be {self.expected}, got {shown(text)}")
        return value + 0.0  # -0.0 -> 0.0


def sequence_id(text: str) -> str:
    """A SemanticKITTI sequence number ``0``..``999999`` -> its folder name (``7`` -> ``07``, ``123`` -> ``123``;
    :data:`generator.formats.semantickitti.MAX_SEQUENCE`, the naming semantic-kitti-api reads)."""
    if not re.fullmatch(r"[0-9]{1,6}", text):
        raise argparse.ArgumentTypeError(f"must be a sequence number 00..999999, got {shown(text)}")
    return f"{int(text):02d}"


def sequence_list(text: str) -> list[str]:
    """``00,01`` -> ``['00', '01']`` (each one a :func:`sequence_id`)."""
    items = [s.strip() for s in text.split(",", MAX_LIST_ITEMS)]
    if not text.strip() or any(not s for s in items) or len(items) > 100:
        raise argparse.ArgumentTypeError(f"must be sequence numbers like 00,01, got {shown(text)}")
    return list(dict.fromkeys(sequence_id(s) for s in items))


sequence_id.kind = "sequence"
sequence_list.kind = "sequence list"


def integer_list(lo: int, hi: int):
    """``type=integer_list(0, 999999)``: comma-separated integers in ``lo..hi`` (``0,3,7``), duplicates dropped."""
    one = Integer(lo, hi)

    def parse(text: str) -> list[int]:
        items = text.split(",", MAX_LIST_ITEMS)
        if len(items) > MAX_LIST_ITEMS or not text.strip():
            raise argparse.ArgumentTypeError(f"must be comma-separated integers in {lo}..{hi}, got {shown(text)}")
        try:
            return list(dict.fromkeys(one(s.strip()) for s in items))
        except argparse.ArgumentTypeError:
            raise argparse.ArgumentTypeError(
                f"must be comma-separated integers in {lo}..{hi}, got {shown(text)}") from None

    parse.__name__ = parse.kind = "integer list"
    return parse


def path(text: str) -> Path:
    """A path named on the command line: not empty (``''`` would silently mean the working
    directory), no NUL byte, at most :data:`MAX_PATH_CHARS` characters, valid UTF-8."""
    if not text:
        raise argparse.ArgumentTypeError("must be a path, got an empty string")
    if "\0" in text:
        raise argparse.ArgumentTypeError(f"must be a path, got one with a NUL byte: {shown(text)}")
    if len(text) > MAX_PATH_CHARS:
        raise argparse.ArgumentTypeError(f"path too long ({len(text)} characters; at most {MAX_PATH_CHARS})")
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:  # bytes that are not UTF-8 (Python keeps them as lone surrogates)
        raise argparse.ArgumentTypeError(f"must be a UTF-8 path (urbangen records paths in its JSON, YAML and "
                                         f"Markdown outputs), got {shown(text)}") from None
    return Path(text)


def text_path(text: str) -> str:
    """:func:`path`, kept as the string the user typed (specs and configs are named as given)."""
    path(text)
    return text


path.kind = text_path.kind = "path"
