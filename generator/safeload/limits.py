"""Size and structure budgets of every user file (see :mod:`generator.safeload`)."""

from __future__ import annotations

import numpy as np

KiB = 1024
MiB = 1024 * KiB
GiB = 1024 * MiB

#: JSON specs and small JSON documents.
MAX_DOCUMENT_BYTES = 4 * MiB
#: YAML files (configs, sensors, profiles, label configs). Lower than JSON because the
#: pure-Python YAML parser (needed for the checks below) reads only ~0.2 MiB/s.
MAX_YAML_BYTES = 1 * MiB
#: Dataset metadata JSON (per image, per sequence, OpenLABEL).
MAX_METADATA_BYTES = 16 * MiB
#: Numeric text tables (poses, times, calibration).
MAX_TABLE_BYTES = 64 * MiB
#: Binary arrays (scans, labels).
MAX_ARRAY_BYTES = 1 * GiB
#: Deepest nesting of lists/mappings in a JSON or YAML document (top level = 1).
MAX_DEPTH = 64
#: YAML alias (``*name``) uses per document.
MAX_ALIASES = 100
#: Values per JSON/YAML document (containers, keys and scalars; YAML aliases counted
#: expanded). The largest shipped file has ~1000; pass more for dataset metadata.
MAX_NODES = 20_000
#: Longest integer literal (digits) accepted before it is even converted.
MAX_INT_DIGITS = 4000

#: The largest finite float64: integers beyond it are refused (they would become inf).
_FLOAT_MAX = float(np.finfo(np.float64).max)
