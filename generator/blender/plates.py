"""Licence plates: a registration per car and the glyphs that print it (numpy only, no fonts).

A car's plates are two boxes of the ``licence_plate`` material in its prototype mesh
(:mod:`assets_procedural.vehicle`), shared by every car of that prototype; what they read is drawn
per object, like the paint finish (:mod:`generator.blender.vehicle_finish`): a German-style EU
registration ``"KA AB 1234"`` (district code, one or two letters, one to four digits, at most eight
characters) from the stream ``stream(seed, "licence_plate", instance_id)``, written as object
properties ``ug_plate_0 .. ug_plate_9`` (the code of each character cell, :data:`CHARSET`) and
``ug_plate_off`` (cells of left padding, so the text is centred).

The ``licence_plate`` recipe (:mod:`generator.blender.recipes_actors`) draws the plate in the
plate's own millimetres (:data:`PLATE_MM`): a dark frame, the blue EU band with its ring of stars
and the country letter at the left, and the characters, each sampled from one packed image, the
glyph atlas of :func:`glyph_atlas`: one cell per character of :data:`CHARSET` (a 5 x 7 dot matrix
whose neighbouring dots are joined by strokes, so diagonals and rounded corners come out as in
a plate's typeface) and one last cell holding the band. The plate's face gets the coordinates it
is drawn in from :func:`plate_uv` (a UV map the edge adds to meshes with plates).

Only the colour changes: the plate's class, material and geometry stay, so the label passes and
the LiDAR see exactly what they saw.
"""

from __future__ import annotations

import functools

import numpy as np

from generator.rng import stream

CHARSET = " 0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZ-"   #: glyph codes: index in this string (0 blank)
BAND_CODE = len(CHARSET)                           #: atlas cell of the EU band
N_CELLS = 10                                       #: character cells on a plate
PLATE_MM = (520.0, 110.0)                          #: EU plate, width x height
FRAME_MM = 2.5                                     #: dark frame at the plate's edge
INNER_MM = (3.0, 107.0)                            #: y range of the band and the character cells
BAND_MM = (3.0, 43.0)                              #: x range of the EU band
TEXT_X0_MM = 47.0                                  #: left end of the first character cell
CELL_MM = 46.8                                     #: width of a character cell (10 cells to 515 mm)
CELL_PX = (104, 48)                                #: atlas cell, rows x columns (about 1 px per mm)
COUNTRY = "D"                                      #: the band's country letter

#: German district codes (a sample of large towns), the first part of a registration
DISTRICTS = ("B", "M", "HH", "K", "F", "S", "D", "DO", "E", "HB", "H", "L", "DD", "N", "KA", "MA", "HD", "BN",
             "MS", "A", "AC", "BI", "BO", "WI", "GE", "MZ", "KI", "HL", "OS", "OL", "FR", "UL", "KS", "PB",
             "GI", "RO", "LB", "ES", "BB", "RV", "TR", "HN", "SB", "BS", "MD", "HRO")

_BITMAPS = {
    "0": ".###.|#...#|#...#|#...#|#...#|#...#|.###.", "1": "..#..|.##..|#.#..|..#..|..#..|..#..|..#..",
    "2": ".###.|#...#|....#|...#.|..#..|.#...|#####", "3": "#####|...#.|..#..|...#.|....#|#...#|.###.",
    "4": "...#.|..##.|.#.#.|#..#.|#####|...#.|...#.", "5": "#####|#....|####.|....#|....#|#...#|.###.",
    "6": "..##.|.#...|#....|####.|#...#|#...#|.###.", "7": "#####|....#|...#.|..#..|.#...|.#...|.#...",
    "8": ".###.|#...#|#...#|.###.|#...#|#...#|.###.", "9": ".###.|#...#|#...#|.####|....#|...#.|.##..",
    "A": ".###.|#...#|#...#|#####|#...#|#...#|#...#", "B": "####.|#...#|#...#|####.|#...#|#...#|####.",
    "C": ".###.|#...#|#....|#....|#....|#...#|.###.", "D": "###..|#..#.|#...#|#...#|#...#|#..#.|###..",
    "E": "#####|#....|#....|####.|#....|#....|#####", "F": "#####|#....|#....|####.|#....|#....|#....",
    "G": ".###.|#...#|#....|#.###|#...#|#...#|.####", "H": "#...#|#...#|#...#|#####|#...#|#...#|#...#",
    "I": "..#..|..#..|..#..|..#..|..#..|..#..|..#..", "J": "..###|...#.|...#.|...#.|...#.|#..#.|.##..",
    "K": "#...#|#..#.|#.#..|##...|#.#..|#..#.|#...#", "L": "#....|#....|#....|#....|#....|#....|#####",
    "M": "#...#|##.##|#.#.#|#.#.#|#...#|#...#|#...#", "N": "#...#|#...#|##..#|#.#.#|#..##|#...#|#...#",
    "O": ".###.|#...#|#...#|#...#|#...#|#...#|.###.", "P": "####.|#...#|#...#|####.|#....|#....|#....",
    "Q": ".###.|#...#|#...#|#...#|#.#.#|#..#.|.##.#", "R": "####.|#...#|#...#|####.|#.#..|#..#.|#...#",
    "S": ".####|#....|#....|.###.|....#|....#|####.", "T": "#####|..#..|..#..|..#..|..#..|..#..|..#..",
    "U": "#...#|#...#|#...#|#...#|#...#|#...#|.###.", "V": "#...#|#...#|#...#|#...#|#...#|.#.#.|..#..",
    "W": "#...#|#...#|#...#|#.#.#|#.#.#|#.#.#|.#.#.", "X": "#...#|#...#|.#.#.|..#..|.#.#.|#...#|#...#",
    "Y": "#...#|#...#|.#.#.|..#..|..#..|..#..|..#..", "Z": "#####|....#|...#.|..#..|.#...|#....|#####",
    "-": ".....|.....|.....|.###.|.....|.....|.....", " ": ".....|.....|.....|.....|.....|.....|.....",
}


def plate_string(seed: int, instance_id: int) -> str:
    """The registration on the plates of the car ``instance_id``: ``"KA AB 1234"``.

    District code (:data:`DISTRICTS`), one or two letters, one to four digits (no leading zero),
    at most eight characters besides the two spaces, as on German plates. Drawn from the stream
    ``stream(seed, "licence_plate", instance_id)``: the same seed and id give the same string.
    """
    g = stream(seed, "licence_plate", int(instance_id))
    district = DISTRICTS[int(g.integers(len(DISTRICTS)))]
    letters = "".join(chr(65 + int(c)) for c in g.integers(26, size=1 + int(g.random() < 0.7)))
    n_digits = min(int(g.choice(4, p=[0.05, 0.15, 0.3, 0.5])) + 1, 8 - len(district) - len(letters))
    digits = str(int(g.integers(1, 10))) + "".join(str(int(d)) for d in g.integers(10, size=n_digits - 1))
    return f"{district} {letters} {digits}"


def plate_codes(text: str) -> tuple[np.ndarray, float]:
    """(N_CELLS,) int glyph codes of ``text`` (blanks padded on the right) and the left padding in cells
    that centres it on the plate."""
    if len(text) > N_CELLS or any(c not in CHARSET for c in text):
        raise ValueError(f"a plate holds up to {N_CELLS} characters of {CHARSET!r}, got {text!r}")
    codes = np.zeros(N_CELLS, np.int64)
    codes[:len(text)] = [CHARSET.index(c) for c in text]
    return codes, (N_CELLS - len(text)) / 2.0


def plate_properties(seed: int, instance_id: int) -> dict[str, float]:
    """The object properties the ``licence_plate`` recipe reads for the car ``instance_id``."""
    codes, off = plate_codes(plate_string(seed, instance_id))
    props = {f"ug_plate_{i}": float(c) for i, c in enumerate(codes)}
    props["ug_plate_off"] = off
    return props


def apply_plates(objects, seed: int) -> int:
    """Write the registration of every car among ``objects`` (Blender objects carrying ``ug_class`` and
    their instance id as ``pass_index``); returns how many got one."""
    n = 0
    for ob in objects:
        if ob.get("ug_class") == "car":
            for key, value in plate_properties(seed, ob.pass_index).items():
                ob[key] = value
            n += 1
    return n


def _strokes(char: str) -> tuple[np.ndarray, np.ndarray]:
    """The dot-matrix glyph of ``char`` as (k, 2) dots (column, row; row 0 at the top) and (s, 2, 2)
    strokes: neighbouring dots joined across, along and diagonally (a diagonal only where no two
    straight strokes already turn that corner)."""
    rows = _BITMAPS[char].split("|")
    on = np.array([[c == "#" for c in r] for r in rows])
    dots = [(c, r) for r in range(7) for c in range(5) if on[r, c]]
    segs = []
    for c, r in dots:
        for dc, dr in ((1, 0), (0, 1)):
            if c + dc < 5 and r + dr < 7 and on[r + dr, c + dc]:
                segs.append(((c, r), (c + dc, r + dr)))
        for dc in (1, -1):
            c2, r2 = c + dc, r + 1
            if 0 <= c2 < 5 and r2 < 7 and on[r2, c2] and not on[r, c2] and not on[r2, c]:
                segs.append(((c, r), (c2, r2)))
    return np.array(dots, float).reshape(-1, 2), np.array(segs, float).reshape(-1, 2, 2)


def _seg_distance(p: np.ndarray, seg: np.ndarray) -> np.ndarray:
    """(n,) distance from each of the (n, 2) points ``p`` to the nearest of the (s, 2, 2) segments."""
    a, b = seg[None, :, 0], seg[None, :, 1]
    ab = b - a
    t = np.clip(np.einsum("nsk,nsk->ns", p[:, None] - a, ab) / np.maximum((ab ** 2).sum(-1), 1e-12), 0, 1)
    return np.linalg.norm(p[:, None] - (a + t[..., None] * ab), axis=-1).min(1)


def glyph_coverage(char: str, shape: tuple[int, int], size_mm: tuple[float, float], box_mm: tuple[float, ...],
                   stroke_mm: float) -> np.ndarray:
    """(rows, cols) float32 ink coverage in [0, 1] of ``char`` drawn in a cell of ``size_mm`` (width,
    height) rasterised at ``shape``; the glyph fills ``box_mm`` = (x0, y0, x1, y1), millimetres from
    the cell's top-left corner, to the outer edge of its strokes (``stroke_mm`` wide), anti-aliased."""
    h, w = shape
    dots, segs = _strokes(char)
    if len(dots) == 0:
        return np.zeros(shape, np.float32)
    x0, y0, x1, y1 = box_mm
    half = stroke_mm / 2
    scale = np.array([(x1 - x0 - stroke_mm) / 4, (y1 - y0 - stroke_mm) / 6])
    origin = np.array([x0 + half, y0 + half])
    px = np.array([size_mm[0] / w, size_mm[1] / h])
    jj, ii = np.meshgrid(np.arange(w), np.arange(h))
    p = np.stack([(jj.ravel() + 0.5) * px[0], (ii.ravel() + 0.5) * px[1]], 1)
    d = np.linalg.norm(p[:, None] - (origin + dots * scale)[None], axis=-1).min(1)
    if len(segs):
        d = np.minimum(d, _seg_distance(p, origin + segs * scale))
    cov = np.clip(0.5 + (half - d) / px.mean(), 0.0, 1.0)
    return cov.reshape(shape).astype(np.float32)


def _band() -> np.ndarray:
    """(rows, cols, 4) float32 the EU band's cell: blue, twelve yellow stars in a ring, the white
    country letter below (linear colours, alpha 1)."""
    h, w = CELL_PX
    bw, bh = BAND_MM[1] - BAND_MM[0], INNER_MM[1] - INNER_MM[0]
    out = np.empty((h, w, 4), np.float32)
    out[:] = (0.0, 0.033, 0.32, 1.0)                      # EU blue (sRGB #003399)
    jj, ii = np.meshgrid((np.arange(w) + 0.5) * bw / w, (np.arange(h) + 0.5) * bh / h)
    a = 2 * np.pi * np.arange(12) / 12
    stars = np.stack([bw / 2 + 11.0 * np.cos(a), 27.0 + 11.0 * np.sin(a)], 1)
    d = np.hypot(jj[..., None] - stars[:, 0], ii[..., None] - stars[:, 1]).min(-1)
    star = np.clip(0.5 + (1.9 - d) / (bw / w), 0, 1)[..., None]
    out[..., :3] = out[..., :3] * (1 - star) + star * np.array([0.95, 0.78, 0.0], np.float32)
    letter = glyph_coverage(COUNTRY, CELL_PX, (bw, bh), (bw / 2 - 9.0, 56.0, bw / 2 + 9.0, 86.0), 4.0)[..., None]
    out[..., :3] = out[..., :3] * (1 - letter) + letter * 0.85
    return out


@functools.cache
def glyph_atlas() -> np.ndarray:
    """(CELL_PX[0], CELL_PX[1] * (len(CHARSET) + 1), 4) float32 RGBA, row 0 at the top: one cell per
    character of :data:`CHARSET` (near-black ink, alpha its coverage; FE-Schrift proportions: 75 mm
    high, 9 mm strokes, letters 34 mm and digits 30 mm wide in a :data:`CELL_MM` cell) and the EU band
    (:data:`BAND_CODE`, opaque). Read-only: made once per process."""
    h, w = CELL_PX
    bh = INNER_MM[1] - INNER_MM[0]
    cells = []
    for ch in CHARSET:
        m = 6.4 + 2.0 * ch.isdigit()           # digits narrower than letters (FE-Schrift: 0 is not O)
        cov = glyph_coverage(ch, CELL_PX, (CELL_MM, bh), (m, (bh - 75) / 2, CELL_MM - m, (bh + 75) / 2), 9.0)
        cell = np.zeros((h, w, 4), np.float32)
        cell[..., :3] = 0.012
        cell[..., 3] = cov
        cells.append(cell)
    cells.append(_band())
    atlas = np.concatenate(cells, 1)
    atlas.flags.writeable = False     # made once per process (a constant), shared by every worker's image
    return atlas


def plate_uv(vertices: np.ndarray, faces: np.ndarray, plate: np.ndarray) -> np.ndarray:
    """(m, 3, 2) float32 per face corner: where on its plate the corner lies, (0, 0) the plate's bottom
    left and (1, 1) its top right seen from outside; (-1, -1) on a plate's edges and back (drawn as
    its frame) and (0, 0) on every other face.

    Parameters
    ----------
    vertices : (n, 3) float
        A vehicle's local frame (+x forward, z up), metres.
    faces : (m, 3) int
    plate : (m,) bool
        The faces of the licence plates: the front plate's ahead of x = 0, the rear's behind it, each an
        axis-aligned box whose outer face looks along +x (front) or -x (rear).
    """
    tri = vertices[faces]
    uv = np.zeros((len(faces), 3, 2), np.float32)
    centre_x = tri[..., 0].mean(1)
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    for sign in (1.0, -1.0):
        sel = plate & (sign * centre_x > 0)
        if not sel.any():
            continue
        pts = tri[sel].reshape(-1, 3)
        (y0, z0), (y1, z1) = pts[:, 1:].min(0), pts[:, 1:].max(0)
        u = (tri[sel][..., 1] - y0) / max(y1 - y0, 1e-9)
        v = (tri[sel][..., 2] - z0) / max(z1 - z0, 1e-9)
        face_uv = np.stack([u if sign > 0 else 1 - u, v], -1)
        n = normal[sel]
        outer = sign * n[:, 0] > 0.9 * np.linalg.norm(n, axis=1)
        face_uv[~outer] = -1.0
        uv[sel] = face_uv
    return uv
