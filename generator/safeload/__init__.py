"""One hardened loading layer for every file a user hands to urbangen.

Specs, render configs, sensor and profile YAML, label configs, metadata JSON, pose and
calibration tables and binary scans all come from outside; a wrong, corrupted or hostile
file must end in one :class:`generator.errors.UserError` line ``<file>: <field>: <reason>``
(exit 2), quickly, without reading the whole of an endless input and without echoing the
file's content. Every reader of user files goes through this module; it is the bottom
layer and imports nothing else of urbangen but :mod:`generator.errors`.

What every file gets
--------------------
* **Regular files only**, checked with :func:`os.stat` before opening and again on the
  open descriptor (opened with ``O_NONBLOCK``, so a FIFO swapped in meanwhile cannot
  block): directories, FIFOs, sockets and devices (``/dev/zero``) are refused.
* **Size limit before reading**; at most ``max_bytes + 1`` bytes are read, so a file that
  grows (or a ``/proc`` file that claims size 0) is still caught.
* Symlink loops, permission problems, NUL bytes in paths: one line each.

Text and documents
------------------
* Strict UTF-8 (a leading byte-order mark is dropped); the message gives the byte offset.
* JSON: duplicate keys, ``NaN``/``Infinity`` and nesting deeper than :data:`MAX_DEPTH`
  are refused; the depth is measured on the text before parsing, so no parser recursion.
* YAML: the safe loader plus duplicate keys refused, aliases limited to
  :data:`MAX_ALIASES` and the expanded document to :data:`MAX_NODES` nodes ("billion
  laughs" fails at once), nesting limited (also through aliases), recursive aliases,
  ``!!binary``/``!!set``/``!!omap``/``!!pairs`` refused, dates kept as strings, keys must be
  strings unless asked otherwise. Errors read ``line L column C: <problem>`` with any
  quoted text of the parser's problem removed: the file's content never appears.
* Parsed data: every float finite, every integer within the float range
  (:func:`check_finite`, which names the field).

Messages
--------
The file is named as the user named it (``source``); control characters in names are
escaped so the message stays one line. Reasons never quote the content of the file.
"""

from generator.safeload.documents import check_finite, load_json, parse_json
from generator.safeload.files import confined_path, read_array, read_bytes, read_matrix_rows, read_text
from generator.safeload.limits import (
                                       MAX_ALIASES,
                                       MAX_ARRAY_BYTES,
                                       MAX_DEPTH,
                                       MAX_DOCUMENT_BYTES,
                                       MAX_INT_DIGITS,
                                       MAX_METADATA_BYTES,
                                       MAX_NODES,
                                       MAX_TABLE_BYTES,
                                       MAX_YAML_BYTES,
                                       GiB,
                                       KiB,
                                       MiB,
)
from generator.safeload.messages import field_path, file_kind, printable
from generator.safeload.yaml_docs import load_package_yaml, load_yaml, parse_yaml

__all__ = [
    "MAX_ALIASES", "MAX_ARRAY_BYTES", "MAX_DEPTH", "MAX_DOCUMENT_BYTES", "MAX_INT_DIGITS", "MAX_METADATA_BYTES",
    "MAX_NODES", "MAX_TABLE_BYTES", "MAX_YAML_BYTES", "GiB", "KiB", "MiB",
    "check_finite", "confined_path", "field_path", "load_json", "load_package_yaml", "load_yaml", "parse_json",
    "parse_yaml",
    "file_kind", "printable", "read_array", "read_bytes", "read_matrix_rows", "read_text",
]
