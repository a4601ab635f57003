"""User-facing errors.

Every error a user can cause (bad spec, bad config, bad path, bad option) is an
:class:`UserError`. The command line prints its message as one line on stderr and
exits with :data:`EXIT_USAGE`; nothing half-written is left behind because every
writer in the package is atomic (see :mod:`generator.atomic`).
"""

from __future__ import annotations

EXIT_USAGE = 2


class UserError(Exception):
    """An error caused by the user's input; the message is shown as is."""

    exit_code = EXIT_USAGE


class SpecError(UserError):
    """A bad field in a spec or config file.

    Parameters
    ----------
    source : str
        The file the value came from (as the user named it).
    field : str
        Dotted path of the field (``town.blocks_x``); empty for whole-file problems.
    reason : str
        Why it is wrong, ending with the offending value where there is one.
    """

    def __init__(self, source: str, field: str, reason: str):
        self.source, self.field, self.reason = str(source), field, reason
        where = f"{self.source}: {field}: " if field else f"{self.source}: "
        super().__init__(where + reason)
