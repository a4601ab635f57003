"""A gallery of one asset library's cars and people, to look at their variety (issue 29).

Draws the first ``--n`` car and person variants of the library a town of the spec builds (town
``--town`` of a re-drawn run, or the spec's one town), side by side at one metric scale: each car
from the side (x-z) above its plan (x-y), each person from the front (y-z) and the side (x-z).
Faces are filled in their material colours and drawn far to near (a silhouette plot, not a
render). Titles give the body type and length x width x height, or the height, age and sex.

Usage::

    python bench/variety_gallery.py scenes/default_town.json OUT_DIR [--town 0] [--n 40]

Writes ``OUT_DIR/cars.png`` and ``OUT_DIR/people.png``; prints the body-type mix and the height
distribution of the library.
"""

from __future__ import annotations

import argparse
import collections
import dataclasses
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import PolyCollection  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from generator.layout.placement.prototypes import Library  # noqa: E402
from generator.layout.placement.variety import car_variant, person_variants, variant_counts  # noqa: E402
from generator.materials import material_table  # noqa: E402
from generator.spec import load_spec  # noqa: E402
from generator.spec.towns import library_seed, town_spec  # noqa: E402


def draw(ax, mesh, axes: tuple[int, int], depth_axis: int, flip_depth: bool = False) -> None:
    """Fill ``mesh``'s faces projected on ``axes`` (coordinate indices), far faces first."""
    tri = mesh.vertices[mesh.faces]
    d = tri[:, :, depth_axis].mean(1) * (-1 if flip_depth else 1)
    order = np.argsort(d)
    colors = np.asarray(material_table().colors, float)[mesh.face_material[order]] / 255.0
    ax.add_collection(PolyCollection(tri[order][:, :, list(axes)], facecolors=colors, edgecolors="none"))


def library_of(spec, town: int | None) -> tuple[object, Library]:
    if town is not None:
        base = spec if spec.town.redraw_every_frames else dataclasses.replace(
            spec, town=dataclasses.replace(spec.town, redraw_every_frames=1))
        spec = town_spec(base, town)
    return spec, Library(library_seed(spec), variant_counts(spec))


def cars(lib: Library, n: int, out: Path) -> None:
    protos = [car_variant(lib, i) for i in range(min(n, lib.count("car", 6)))]
    cols = 8
    rows = int(np.ceil(len(protos) / cols))
    fig, axs = plt.subplots(2 * rows, cols, figsize=(2.6 * cols, 2.4 * rows), squeeze=False,
                            gridspec_kw={"height_ratios": [1.0, 1.1] * rows})
    mix = collections.Counter()
    for k, p in enumerate(protos):
        body = _body(p)
        mix[body] += 1
        size = p.hi - p.lo
        side, top = axs[2 * (k // cols), k % cols], axs[2 * (k // cols) + 1, k % cols]
        draw(side, p.mesh, (0, 2), 1, flip_depth=True)        # seen from -y: near = small y
        draw(top, p.mesh, (0, 1), 2)                          # from above: near = high z
        side.set_title(f"{p.key} {body}\n{size[0]:.2f} x {size[1]:.2f} x {size[2]:.2f} m", fontsize=7)
        _tile(side, (-2.9, 2.9), (-0.1, 2.1))
        _tile(top, (-2.9, 2.9), (-1.3, 1.3))
    _save(fig, axs, 2 * len(protos),
          f"{len(protos)} car variants of library seed {lib.seed} (side, plan; one scale: 5.8 m wide tiles)", out)
    print("car body types:", dict(mix))


def _tile(a, xlim: tuple[float, float], ylim: tuple[float, float]) -> None:
    """One gallery tile: these limits (metres), equal axes, no ticks."""
    a.set_xlim(*xlim)
    a.set_ylim(*ylim)
    a.set_aspect("equal")
    a.set_xticks([])
    a.set_yticks([])


def _save(fig, axs, used: int, title: str, out: Path) -> None:
    """Blank the tiles past the first ``used``, title the sheet and write it to ``out``."""
    for a in axs.flat[used:]:
        a.axis("off")
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(out, dpi=80)
    plt.close(fig)


def _body(p) -> str:
    """The body type of a car prototype (from its quantile, as the builder picks it)."""
    from assets_procedural.vehicle import CAR_VARIANTS
    names = list(CAR_VARIANTS)
    cum = np.cumsum(list(CAR_VARIANTS.values()))
    return names[int(np.searchsorted(cum / cum[-1], p.params["quantile"], side="right"))]


def people(lib: Library, spec, n: int, out: Path) -> None:
    protos = person_variants(lib, spec)[:n]
    cols = 10
    rows = int(np.ceil(len(protos) / cols))
    fig, axs = plt.subplots(rows, 2 * cols, figsize=(1.3 * 2 * cols, 2.8 * rows), squeeze=False)
    heights = []
    for k, p in enumerate(protos):
        front, side = axs[k // cols, 2 * (k % cols)], axs[k // cols, 2 * (k % cols) + 1]
        draw(front, p.mesh, (1, 2), 0)                       # seen from +x: near = high x
        draw(side, p.mesh, (0, 2), 1, flip_depth=True)
        pr = p.params
        heights.append(pr["height"])
        front.set_title(f"{pr['height']:.2f} m {pr['age']:.0f} y {pr['sex'][0]}\n{pr['pose'][:4]}", fontsize=7)
        for a in (front, side):
            _tile(a, (-0.55, 0.55), (-0.02, 2.05))
    title = f"{len(protos)} person variants of library seed {lib.seed} (front, side; one scale)"
    _save(fig, axs, 2 * len(protos), title, out)
    h = np.array(heights)
    print(f"people: {len(h)}, heights {h.min():.2f}-{h.max():.2f} m, children {(h < 1.5).sum()}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("spec")
    ap.add_argument("out", type=Path)
    ap.add_argument("--town", type=int, default=None, help="town index of a re-drawn run (default: the one town)")
    ap.add_argument("--n", type=int, default=40)
    args = ap.parse_args(argv)
    spec, lib = library_of(load_spec(args.spec), args.town)
    args.out.mkdir(parents=True, exist_ok=True)
    cars(lib, args.n, args.out / "cars.png")
    people(lib, spec, args.n, args.out / "people.png")
    print(f"wrote {args.out / 'cars.png'} and {args.out / 'people.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
