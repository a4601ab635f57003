"""The arithmetic the pinned scene digests were recorded with, so any x86-64 machine can check them.

A scene's bytes depend on the machine's floating point below the last bit: numpy's BLAS picks a
matrix-product kernel for the CPU it finds (OpenBLAS: ``Haswell`` on AMD Zen and older Intel,
a generic ``Prescott`` kernel on CPUs it does not know, ``SkylakeX`` ...), and those kernels round
``(n, 3) @ (3, 3)`` and ``4 x 4`` products differently; numpy's own vectorised ``exp``, ``log``,
``arctan2``, ``power`` ... differ between AVX-512 and AVX2 machines. Same spec and seed give the
same bytes on one kind of machine, not across kinds.

The digests pinned in ``bench/town_digests.json`` and the tests were recorded on an AVX-512 machine
with OpenBLAS's ``Haswell`` kernels. :func:`reference_env` gives the environment that reproduces
that arithmetic in a fresh process (``OPENBLAS_CORETYPE`` must be set before numpy loads), or
None where it cannot be reproduced.
"""

from __future__ import annotations

import os
import platform
from pathlib import Path

#: What the reference machine had.
CORETYPE = "Haswell"
NEEDED_FLAGS = ("avx2", "fma", "avx512f")


def _cpu_flags() -> set[str]:
    try:
        text = Path("/proc/cpuinfo").read_text()
    except OSError:
        return set()
    for line in text.splitlines():
        if line.startswith("flags"):
            return set(line.split(":", 1)[1].split())
    return set()


def reference_env() -> dict[str, str] | None:
    """Environment for a subprocess that computes with the reference arithmetic, or None (another
    architecture, or a CPU without AVX2/FMA/AVX-512: the pinned digests cannot be checked there)."""
    if platform.machine() not in ("x86_64", "AMD64") or not set(NEEDED_FLAGS) <= _cpu_flags():
        return None
    return {**os.environ, "OPENBLAS_CORETYPE": CORETYPE}


def why_not() -> str:
    """The reason a pinned digest is not checked on this machine."""
    return (f"pinned digests need an x86-64 CPU with {', '.join(NEEDED_FLAGS)} "
            f"(this one: {platform.machine()}; see tests/kits/reference_arithmetic.py)")
