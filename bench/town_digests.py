"""Digests of a fixed set of towns, to hold a speed-up to the bytes of the code before it.

    python bench/town_digests.py            # compare with bench/town_digests.json (exit 1 on a change)
    python bench/town_digests.py --write    # record the current code's digests (do this on main's code)

The set: the default town and kitti_like as they are, both at other seeds, the towns 1..3 of a
re-drawn run of each (``town.redraw_every_frames``: a town seed, and each town its own asset
library, ``assets.redraw_every_towns`` 1; built one after the other as in a real run), a 2x2 and a 4x4
default town, and the test town and city centre. Every build goes through
:func:`generator.layout.assemble.build_scene` and :meth:`SceneModel.digest` (every triangle,
class, material, instance, label hull, object record and route). The digests were recorded with
the arithmetic of tests/kits/reference_arithmetic.py; the script re-runs itself with it.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

from kits.reference_arithmetic import reference_env, why_not  # noqa: E402

if __name__ == "__main__" and "OPENBLAS_CORETYPE" not in os.environ:   # before numpy loads
    _env = reference_env()
    if _env is None:
        sys.exit(f"cannot check the pinned digests here: {why_not()}")
    os.execve(sys.executable, [sys.executable, *sys.argv], _env)

from generator.layout.assemble import build_scene  # noqa: E402
from generator.spec import load_spec  # noqa: E402
from generator.spec.towns import town_spec  # noqa: E402

REFERENCE = Path(__file__).with_name("town_digests.json")


def town_set(root: Path = ROOT):
    """``(name, spec)`` of every town of the set, in build order."""
    out = []
    for scene in ("default_town", "kitti_like"):
        base = load_spec(root / "scenes" / f"{scene}.json")
        out.append((scene, base))
        for seed in (1, 7, 123456789):
            out.append((f"{scene}@seed{seed}", dataclasses.replace(base, seed=seed)))
        redraw = dataclasses.replace(base, town=dataclasses.replace(base.town, redraw_every_frames=1))
        for i in range(4):
            out.append((f"{scene}/town{i}", town_spec(redraw, i)))
    base = load_spec(root / "scenes" / "default_town.json")
    for n in (2, 4):
        out.append((f"default_town_{n}x{n}", dataclasses.replace(base, town=dataclasses.replace(base.town, blocks_x=n,
                                                                                               blocks_y=n))))
    for scene in ("test_town", "city_centre"):
        out.append((scene, load_spec(root / "scenes" / f"{scene}.json")))
    return out


def digests(root: Path = ROOT) -> dict[str, str]:
    """Name -> digest of every town of :func:`town_set`."""
    out = {}
    for name, spec in town_set(root):
        t0 = time.perf_counter()
        out[name] = build_scene(spec).digest()
        print(f"{name:>28} {out[name][:16]} {time.perf_counter() - t0:6.2f} s", flush=True)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--write", action="store_true", help="record the digests instead of checking them")
    ap.add_argument("--scenes", default=str(ROOT), help="checkout whose scenes/ to read (default: this one)")
    args = ap.parse_args(argv)
    got = digests(Path(args.scenes))
    if args.write:
        REFERENCE.write_text(json.dumps(got, indent=1) + "\n")
        print(f"wrote {REFERENCE}")
        return 0
    want = json.loads(REFERENCE.read_text())
    bad = [n for n in want if got.get(n) != want[n]]
    print(f"{len(want) - len(bad)} / {len(want)} towns byte-identical to {REFERENCE.name}"
          + (f"; CHANGED: {', '.join(bad)}" if bad else ""))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
