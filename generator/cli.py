"""The ``urbangen`` command line.

Each sub-command lives in ``generator/commands/<name>.py`` and exposes
``register(subparsers)``, which adds its parser and sets ``func`` to a function
``run(args) -> int``. Every user error ends as one line on stderr and exit code 2.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import re
import sys

from generator import __version__
from generator.errors import EXIT_USAGE, UserError

#: Sub-command modules, in the order ``urbangen --help`` lists them.
COMMANDS = [
    "generate",
    "validate",
    "preview",
    "layout",
    "lidar",
    "intensity",
    "convert",
    "import_carla",
    "fuse",
    "eval",
    "export",
    "openlabel",
    "render",
    "stats",
]

log = logging.getLogger("urbangen")


class OneLineParser(argparse.ArgumentParser):
    """An argument parser whose errors are one line and exit code 2."""

    def error(self, message: str):  # noqa: D102 - argparse API
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message}\n")


_ROLE = re.compile(r":([a-z]+):`~?([^`]+)`")
_LITERAL = re.compile(r"``([^`]+)``")


def plain(text: str | None) -> str | None:
    """Help text without reST markup (``:func:`x``` -> ``x``, double backticks dropped)."""
    if not text:
        return text
    def role(m: re.Match) -> str:  # a module keeps its dotted name, a function or class its own name
        return m.group(2) if m.group(1) == "mod" else m.group(2).rsplit(".", 1)[-1]

    return _LITERAL.sub(r"\1", _ROLE.sub(role, text))


def _plain_help(parser: argparse.ArgumentParser) -> None:
    """Strip reST markup from every description and option help of ``parser`` and its sub-commands."""
    parser.description = plain(parser.description)
    for action in parser._actions:
        action.help = plain(action.help)
        if isinstance(action, argparse._SubParsersAction):
            for choice in action._choices_actions:
                choice.help = plain(choice.help)
            for sub in set(action.choices.values()):
                _plain_help(sub)


def build_parser() -> argparse.ArgumentParser:
    parser = OneLineParser(prog="urbangen", description="Procedural urban scenes: labelled images and LiDAR from one geometry.")
    parser.add_argument("--version", action="version", version=f"urbangen {__version__}")
    parser.add_argument("-v", "--verbose", action="count", default=0, help="log progress (-v) or debug details (-vv)")
    parser.add_argument("-q", "--quiet", action="store_true", help="only errors")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=OneLineParser)
    sub.required = True
    for name in COMMANDS:
        importlib.import_module(f"generator.commands.{name}").register(sub)
    _plain_help(parser)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    level = logging.ERROR if args.quiet else (logging.WARNING, logging.INFO, logging.DEBUG)[min(args.verbose, 2)]
    logging.basicConfig(level=level, format="%(levelname)s %(name)s: %(message)s", stream=sys.stderr)
    # progress lines (logged only when stderr is not a terminal; a terminal gets a bar) unless --quiet
    logging.getLogger("urbangen.progress").setLevel(logging.ERROR if args.quiet else logging.INFO)
    try:
        return int(args.func(args) or 0)
    except UserError as e:
        print(f"urbangen {args.command}: {e}", file=sys.stderr)
        return e.exit_code
    except KeyboardInterrupt:
        print("urbangen: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
