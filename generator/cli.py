"""The ``urbangen`` command line.

Each sub-command lives in ``generator/commands/<name>.py`` and exposes
``register(subparsers)``, which adds its parser and sets ``func`` to a function
``run(args) -> int``. :func:`main` returns the exit code and never raises:

* 0 done; 1 ``validate``/``stats --verify`` found problems (listed, one per line);
* 2 bad input -- an option (argparse), a file (:class:`~generator.errors.UserError`) or a
  path the system refused (:class:`OSError`: permission denied, read-only file system, no
  space left, a file where a folder belongs): one line ``urbangen CMD: <what>: <reason>``;
* 130 interrupted (Ctrl-C): one line; staged outputs are removed on the way out;
* 70 anything else is a bug in urbangen: one line saying so and where the traceback went
  (a log file in the temporary folder; ``-v`` also prints it).
"""

from __future__ import annotations

import argparse
import datetime
import importlib
import logging
import os
import re
import sys
import tempfile
import traceback

from generator import __version__
from generator.errors import EXIT_USAGE, UserError
from generator.safeload import printable

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
    "flow",
    "eval",
    "gap",
    "export",
    "process",
    "openlabel",
    "render",
    "stats",
]

log = logging.getLogger("urbangen")

#: Exit codes besides 0, 1 (findings) and 2 (:data:`generator.errors.EXIT_USAGE`).
EXIT_INTERRUPTED = 130
EXIT_BUG = 70  # EX_SOFTWARE of sysexits.h
#: Longest error line printed (a hostile argument must not flood the terminal).
MAX_MESSAGE_CHARS = 2000


class OneLineParser(argparse.ArgumentParser):
    """An argument parser whose errors are one line (``urbangen CMD: --opt: reason``) and exit code 2."""

    def error(self, message: str):  # noqa: D102 - argparse API
        message = message.removeprefix("argument ")
        self.exit(EXIT_USAGE, f"{self.prog}: {printable(message, MAX_MESSAGE_CHARS)}\n")

    def _get_values(self, action, arg_strings):  # noqa: D102 - argparse API
        # Python 3.11's argparse drops a "--" given as an option's value (--frames=--) and then
        # hands the option an empty list instead of a value; refuse it like a missing value.
        if action.option_strings and action.nargs in (None, argparse.ONE_OR_MORE) and arg_strings \
                and all(a == "--" for a in arg_strings):
            raise argparse.ArgumentError(action, "expected a value, got '--'")
        return super()._get_values(action, arg_strings)


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
    parser = OneLineParser(
        prog="urbangen", description="Procedural urban scenes: labelled images and LiDAR from one geometry."
    )
    parser.add_argument("--version", action="version", version=f"urbangen {__version__}")
    parser.add_argument("-v", "--verbose", action="count", default=0, help="log progress (-v) or debug details (-vv)")
    parser.add_argument("-q", "--quiet", action="store_true", help="only errors")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=OneLineParser)
    sub.required = True
    for name in COMMANDS:
        importlib.import_module(f"generator.commands.{name}").register(sub)
    _plain_help(parser)
    _name_leaves(parser)
    return parser


def _name_leaves(parser: argparse.ArgumentParser) -> None:
    """Every runnable (sub-)command records its name (``urbangen intensity fit``) for its messages."""
    subs = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    if not subs:
        parser.set_defaults(command_name=parser.prog)
    for action in subs:
        for sub in set(action.choices.values()):
            _name_leaves(sub)


def main(argv: list[str] | None = None) -> int:
    """Run ``urbangen argv``; return the exit code (see the module docstring). Never raises."""
    _tolerant_output()
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as e:  # argparse: --help, --version, or one line about a bad option
        return e.code if isinstance(e.code, int) else EXIT_USAGE
    level = logging.ERROR if args.quiet else (logging.WARNING, logging.INFO, logging.DEBUG)[min(args.verbose, 2)]
    logging.basicConfig(level=level, format="%(levelname)s %(name)s: %(message)s", stream=sys.stderr)
    # progress lines (logged only when stderr is not a terminal; a terminal gets a bar) unless --quiet
    logging.getLogger("urbangen.progress").setLevel(logging.ERROR if args.quiet else logging.INFO)
    name = getattr(args, "command_name", f"urbangen {args.command}")
    try:
        return int(args.func(args) or 0)
    except UserError as e:
        return _say(name, str(e), e.exit_code)
    except KeyboardInterrupt:
        return _say(name, "interrupted", EXIT_INTERRUPTED)
    except BrokenPipeError:  # output piped into a reader that stopped (| head): nothing more to say
        return _quiet_pipe()
    except OSError as e:  # a path the user gave that the system refused: permission, read-only, full, ...
        from generator.commands.preflight import describe_os_error

        return _say(name, describe_os_error(e), EXIT_USAGE)
    except Exception as e:  # noqa: BLE001 - a bug: one line, the traceback kept
        return _bug(name, e, argv, args.verbose)


def _say(name: str, message: str, code: int) -> int:
    print(f"{name}: {printable(message, MAX_MESSAGE_CHARS)}", file=sys.stderr, flush=True)
    return code


def _tolerant_output() -> None:
    """Never die printing a path: undecodable file names (lone surrogates) come out escaped."""
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.reconfigure(errors="backslashreplace")
        except (AttributeError, ValueError, OSError):  # a captured or detached stream
            pass


def _quiet_pipe() -> int:
    try:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # no second error at exit
    except (OSError, ValueError, AttributeError):
        pass
    return 141  # 128 + SIGPIPE, what a shell reports for a writer that lost its reader


def _bug(name: str, exc: BaseException, argv, verbose: int) -> int:
    """Report an unexpected exception: one line; the traceback in a log file (and on stderr with ``-v``)."""
    text = "".join(traceback.format_exception(type(exc), exc, exc.__traceback__))
    where = None
    try:
        fd, where = tempfile.mkstemp(prefix="urbangen-crash-", suffix=".log")
        with os.fdopen(fd, "w", encoding="utf-8", errors="backslashreplace") as f:
            f.write(f"urbangen {__version__}, {datetime.datetime.now().isoformat(timespec='seconds')}\n"
                    f"command line: {printable(sys.argv if argv is None else argv, 20000)}\n\n{text}")
    except OSError:
        where = None
    if verbose:
        sys.stderr.write(text)
    kept = f"the traceback is in {where}" if where else "rerun with -v to see the traceback"
    return _say(name, f"internal error ({type(exc).__name__}), a bug in urbangen, not in your input; {kept}; "
                      "please report it", EXIT_BUG)


if __name__ == "__main__":
    sys.exit(main())
