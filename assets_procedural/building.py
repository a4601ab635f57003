"""Buildings: extruded footprints with recessed, framed windows, a front door and a roof.

Local frame: metres, z up, origin on the ground near the footprint centre (the footprint
is used as given), the front (the door) on the edge(s) facing -y. Every face is class
``building``. Windows are holes in the wall with reveals, a frame ring and one separate
glass quad per window (material ``window_glass``) 12-18 cm behind the wall plane, so no
face is closer than 2 cm to a parallel face of another material.

The window rhythm, shop fronts and balconies are drawn per building
(:mod:`assets_procedural.facade_layout`); what stands proud of the wall (balconies, sign
boards, blade signs, awnings) is drawn by :mod:`assets_procedural.facade_details`; window
surrounds and rainwater pipes by :mod:`assets_procedural.facade_trim`, from sub-streams of the
building's generator of their own (the window rhythm of a seed does not depend on them).
"""

from __future__ import annotations

import logging

import numpy as np

from assets_procedural.building_roof import flat_roof, pitched_roof, rectangle_of
from assets_procedural.facade_details import balcony, shop_front
from assets_procedural.facade_layout import PIER_M, Hole, Style, draw_style, holes, wall_rects
from assets_procedural.facade_trim import TRIM_T, draw_trim, pipes, surround
from generator.geometry import Mesh, box, merge, quads, resolve_ids
from generator.geometry.primitives import _UNIT_BOX_FACES
from generator.geometry.primitives import _UNIT_BOX_VERTICES as _UNIT_BOX
from generator.rng import substream

log = logging.getLogger(__name__)

CLS = "building"
FACADES = {"plaster": "facade_plaster", "brick": "facade_brick", "concrete": "facade_concrete", "glass": "facade_glass"}
ROOFS = ("flat", "gable", "hip")
FRAME_W = 0.06          # width of the frame ring, metres
FRAME_FROM_GLASS = 0.03  # frame ring sits this far in front of the glass


def _clean(footprint: np.ndarray) -> np.ndarray:
    """Drop repeated and collinear vertices; return the polygon counter-clockwise."""
    p = np.asarray(footprint, float).reshape(-1, 2)
    if len(p) < 3 or not np.all(np.isfinite(p)):
        raise ValueError(f"footprint must be a (k>=3, 2) finite polygon, got shape {p.shape}")
    area = 0.5 * np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1])
    if area < 0:
        p = p[::-1]
    keep = []
    for i in range(len(p)):
        a, b, c = p[i - 1], p[i], p[(i + 1) % len(p)]
        cross = (b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0])
        if np.linalg.norm(b - a) > 1e-6 and abs(cross) > 1e-9:
            keep.append(b)
    p = np.array(keep)
    if len(p) < 3 or abs(area) < 1.0:
        raise ValueError("footprint is degenerate (area < 1 m^2)")
    return p


class _Facade:
    """Maps facade coordinates (u along the edge, v up, w outward) to the local frame.

    Quads are collected (corners, material, facing) and turned into one mesh at the end:
    a facade has hundreds of them.
    """

    def __init__(self, p0: np.ndarray, p1: np.ndarray):
        d = p1 - p0
        self.length = float(np.linalg.norm(d))
        self.d = np.array([d[0], d[1], 0.0]) / self.length
        self.n = np.array([self.d[1], -self.d[0], 0.0])  # outward for a CCW footprint
        self.o = np.array([p0[0], p0[1], 0.0])
        self._axes = [tuple(float(x) for x in c) for c in zip(self.o, self.d, (0.0, 0.0, 1.0), self.n, strict=False)]
        self._up, self._down, self._back = np.array([0, 0, 1.0]), -np.array([0, 0, 1.0]), -self.d
        # quads are collected as 12 facade coordinates each (4 corners of (u, v, w)), mapped in mesh();
        # the direction each faces is an index into _normals (one array per direction, not per quad)
        self.quads: list[tuple] = []
        self.materials: list[str] = []
        self.facing: list[int] = []
        self._normals: list[np.ndarray] = [self.n, self._down, self.d, self._back, self._up]
        self._normal_of: dict[int, int] = {id(a): i for i, a in enumerate(self._normals)}
        self.sills: list[tuple[Hole, str, float]] = []
        self.boxes: list[tuple] = []  # boxes proud of the wall (balconies, sign bands), built in mesh()

    def point(self, u: float, v: float, w: float) -> tuple[float, float, float]:
        """One point (a pane centre, the door) in the local frame: the float operations of :meth:`pts`
        (o + u d + v z + w n, left to right), without arrays."""
        u, v, w = float(u), float(v), float(w)
        return tuple(o + u * d + v * z + w * n for o, d, z, n in self._axes)

    def pts(self, uvw: list[tuple[float, float, float]]) -> np.ndarray:
        """(k, 3) local points of facade coordinates ``uvw`` (k triples)."""
        if len(uvw) == 1:
            return np.array([self.point(*uvw[0])])
        a = np.asarray(uvw, float)
        return self.o + a[:, :1] * self.d + a[:, 1:2] * np.array([0, 0, 1.0]) + a[:, 2:3] * self.n

    def add(self, uvw: list[tuple[float, float, float]], material: str, facing: np.ndarray) -> None:
        """A quad of 4 corners (u, v, w), wound to face ``facing`` ((3,) local frame)."""
        k = self._normal_of.get(id(facing))
        if k is None:  # a new direction (awnings): kept referenced, so its id stays its own
            k = self._normal_of[id(facing)] = len(self._normals)
            self._normals.append(np.asarray(facing, float))
        self.quads.append(tuple(x for p in uvw for x in p))
        self.materials.append(material)
        self.facing.append(k)

    def rect(self, u0, u1, v0, v1, w, material) -> None:
        """Quad in the plane at offset ``w``, facing outward."""
        self.quads.append((u0, v0, w, u1, v0, w, u1, v1, w, u0, v1, w))
        self.materials.append(material)
        self.facing.append(0)

    def ring(self, u0, u1, v0, v1, w, width, material) -> None:
        """A flat frame ring of ``width`` inside the rectangle, facing outward."""
        self.rect(u0, u1, v0, v0 + width, w, material)
        self.rect(u0, u1, v1 - width, v1, w, material)
        self.rect(u0, u0 + width, v0 + width, v1 - width, w, material)
        self.rect(u1 - width, u1, v0 + width, v1 - width, w, material)

    def reveals(self, h: Hole, depth: float, material: str, front: float = 0.0) -> None:
        """The four (three for a door) inner faces of the opening, facing into it; top and sides
        start at ``w = front`` (through a window surround proud of the wall), the bottom at the wall."""
        u0, u1, v0, v1, d, f = h.u0, h.u1, h.v0, h.v1, -depth, front
        q = [(u0, v1, f, u1, v1, f, u1, v1, d, u0, v1, d),       # top, facing down
             (u0, v0, f, u0, v1, f, u0, v1, d, u0, v0, d),       # left, facing along the wall
             (u1, v0, f, u1, v1, f, u1, v1, d, u1, v0, d)]       # right, facing back
        facing = [1, 2, 3]
        if v0 > 0:
            q.append((u0, v0, 0, u1, v0, 0, u1, v0, d, u0, v0, d))  # bottom, facing up
            facing.append(4)
        self.quads += q
        self.materials += [material] * len(q)
        self.facing += facing

    def sill(self, h: Hole, material: str, reach: float = 0.05) -> None:
        """A stone sill under a window, ``reach`` past each side of it, proud of the wall (top, front,
        bottom, ends); built in :meth:`mesh`."""
        self.sills.append((h, material, reach))

    def _sill_mesh(self) -> list[Mesh]:
        """Every sill at once: one box per distinct width (the face against the wall dropped), moved
        to each window -- the same arithmetic per sill as building each box on its own."""
        if not self.sills:
            return []
        # box frame (x along u, -y outward, z up) -> local frame (right-handed: d x -n = z)
        m = np.eye(4)
        m[:3, 0], m[:3, 1], m[:3, 2] = self.d, -self.n, (0, 0, 1.0)
        shapes: dict[tuple[float, str], int] = {}
        built = []
        which = np.empty(len(self.sills), np.int64)
        for i, (h, material, reach) in enumerate(self.sills):
            w = h.u1 - h.u0 + 2 * reach
            if (w, material) not in shapes:
                s = box((w, 0.07, 0.06), CLS, material, center=(0, 0, 0))
                keep = s.vertices[s.faces].mean(1)[:, 1] < 0.035 - 1e-9  # drop the face against the wall
                shapes[(w, material)] = len(built)
                built.append((s.vertices @ m[:3, :3].T, s.faces[keep], s.face_class[keep], s.face_material[keep]))
            which[i] = shapes[(w, material)]
        sills = np.array([((h.u0 + h.u1) / 2, h.v0 - 0.03) for h, _, _ in self.sills])
        # the sill centres, operation by operation as o + uc * d + 0.035 * n + (v0 - 0.03) * z
        centre = self.o + sills[:, :1] * self.d + 0.035 * self.n + sills[:, 1:] * np.array([0, 0, 1.0])
        verts = np.stack([b[0] for b in built])[which] + centre[:, None, :]
        offsets = 8 * np.arange(len(which))
        if len({len(b[1]) for b in built}) == 1:  # the usual case: every shape keeps the same faces
            faces = (np.stack([b[1] for b in built])[which] + offsets[:, None, None]).reshape(-1, 3)
            fcls = np.stack([b[2] for b in built])[which].ravel()
            fmat = np.stack([b[3] for b in built])[which].ravel()
        else:
            faces = np.concatenate([built[k][1] + o for k, o in zip(which, offsets, strict=False)])
            fcls = np.concatenate([built[k][2] for k in which])
            fmat = np.concatenate([built[k][3] for k in which])
        return [Mesh(verts.reshape(-1, 3), faces, fcls, fmat)]

    def box(self, u0, u1, v0, v1, w0, w1, material) -> None:
        """A box spanning [u0, u1] x [v0, v1] x [w0, w1] in facade coordinates (no face against the wall);
        built in :meth:`mesh`."""
        self.boxes.append((u0, u1, v0, v1, w0, w1, material))

    def _box_mesh(self) -> list[Mesh]:
        """Every box at once, in the order drawn. Per box the same arithmetic as building it alone
        (``box(size).transformed(m)``: unit-box corners scaled, the 8 x 3 corners times the wall's
        rotation -- the same (8, 3) @ (3, 3) product per box, stacked --, plus its centre), without
        three intermediate meshes per box: a town draws ~8k of them."""
        if not self.boxes:
            return []
        b = np.array([r[:6] for r in self.boxes], np.float64)
        u0, u1, v0, v1, w0, w1 = b.T
        size = np.stack([u1 - u0, w1 - w0, v1 - v0], 1)
        verts = (_UNIT_BOX - 0.5)[None] * size[:, None, :] + np.zeros(3)
        faces = np.broadcast_to(_UNIT_BOX_FACES, (len(b), 12, 3))
        keep = np.ones((len(b), 12), bool)
        wall = w0 <= 1e-9  # the face against the wall is dropped
        if wall.any():
            centroid_y = verts[wall][:, _UNIT_BOX_FACES].mean(2)[..., 1]
            keep[wall] = centroid_y < (size[wall, 1:2] / 2 - 1e-9)
        m = np.eye(4)
        m[:3, 0], m[:3, 1], m[:3, 2] = self.d, -self.n, (0, 0, 1.0)
        centre = (self.o + ((u0 + u1) / 2)[:, None] * self.d + ((w0 + w1) / 2)[:, None] * self.n
                  + ((v0 + v1) / 2)[:, None] * np.array([0, 0, 1.0]))
        verts = verts @ m[:3, :3].T + centre[:, None, :]
        faces = (faces + 8 * np.arange(len(b))[:, None, None])[keep]
        mats = np.array([resolve_ids(CLS, r[6])[1] for r in self.boxes])
        fmat = np.broadcast_to(mats[:, None], keep.shape)[keep]
        return [Mesh(verts.reshape(-1, 3), faces, resolve_ids(CLS, "default")[0], fmat)]

    def meshes(self) -> list[Mesh]:
        """The wall's quads, sills and boxes (merged by the caller with the other walls: one
        concatenation per building instead of one per wall and one per building)."""
        if self.quads:
            corners = self.pts(np.array(self.quads, float).reshape(-1, 3)).reshape(-1, 4, 3)
            normals = np.array(self._normals)[self.facing]
        else:
            corners, normals = np.zeros((0, 4, 3)), np.zeros((0, 3))
        return [quads(corners, CLS, self.materials, normals)] + self._sill_mesh() + self._box_mesh()


def _opening(fc: _Facade, h: Hole, st: Style, facade_mat: str, trim: float = 0.0) -> np.ndarray:
    """Reveals, frame, glass (or door leaf) of one hole, a surround of bars ``trim`` wide round a
    window (0: none); returns the pane centre (3,)."""
    depth = st.recess
    trimmed = trim > 0 and h.kind == "window" and st.pattern != "ribbon"
    if st.paired:       # the two windows of a pair stand PIER_M apart: bars and sills keep 4 cm between them
        trim = min(trim, PIER_M / 2 - 0.04)
    reach = min(trim + 0.03, PIER_M / 2 - 0.02) if trimmed else 0.05
    fc.reveals(h, depth, facade_mat, TRIM_T if trimmed else 0.0)
    if trimmed:
        surround(fc, h, trim, "facade_trim")
    centre = fc.point((h.u0 + h.u1) / 2, (h.v0 + h.v1) / 2, -depth)
    wf = -depth + FRAME_FROM_GLASS
    if h.kind == "door":
        fc.rect(h.u0, h.u1, h.v0, h.v1, -depth, "door")
        fc.rect(h.u0, h.u1, h.v1 - FRAME_W, h.v1, wf, "window_frame")
        fc.rect(h.u0, h.u0 + FRAME_W, h.v0, h.v1 - FRAME_W, wf, "window_frame")
        fc.rect(h.u1 - FRAME_W, h.u1, h.v0, h.v1 - FRAME_W, wf, "window_frame")
        return centre
    fc.rect(h.u0, h.u1, h.v0, h.v1, -depth, "shop_glass" if h.kind == "shop" else "window_glass")
    fc.ring(h.u0, h.u1, h.v0, h.v1, wf, FRAME_W, "window_frame")
    a, b, c, e = h.u0 + FRAME_W, h.u1 - FRAME_W, h.v0 + FRAME_W, h.v1 - FRAME_W
    um = (h.u0 + h.u1) / 2
    if st.pattern in ("mullion", "cross") or h.kind in ("shop", "balcony"):
        fc.rect(um - 0.03, um + 0.03, c, e, wf, "window_frame")
    if st.pattern == "cross" and h.kind == "window":
        vt = h.v0 + 0.68 * (h.v1 - h.v0)
        fc.rect(a, um - 0.03, vt - 0.03, vt + 0.03, wf, "window_frame")
        fc.rect(um + 0.03, b, vt - 0.03, vt + 0.03, wf, "window_frame")
    if h.kind == "window" and st.pattern != "ribbon":
        fc.sill(h, "facade_trim" if trimmed else "facade_concrete", reach)
    return centre


def building(rng: np.random.Generator, footprint: np.ndarray, height: float, floor_height: float = 3.2,
             facade: str = "plaster", roof: str = "flat") -> Mesh:
    """A building on ``footprint``: walls with windows on every floor, a door on the front, a roof.

    Parameters
    ----------
    rng : numpy.random.Generator
        Source of every random choice (window rhythm, parapet, roof pitch, chimney).
    footprint : (k, 2) float
        Simple polygon, local metres, counter-clockwise (a clockwise one is reversed).
    height : float
        Wall height in metres (top of the parapet for flat roofs; the eaves for gable and
        hip roofs, whose ridge rises above it).
    floor_height : float
        Storey height in metres; one row of windows per storey.
    facade : {"plaster", "brick", "concrete", "glass"}
        Wall material ("glass": a curtain wall of ribbon windows and glass spandrels).
    roof : {"flat", "gable", "hip"}
        Pitched roofs need a rectangular footprint; other footprints get a flat roof.

    Returns
    -------
    Mesh
        Class ``building``; anchors ``"door"`` (1, 3): bottom centre of the door in the wall
        plane, and ``"windows"`` (n, 3): centres of the glass panes (windows, balcony doors,
        shop windows). Shop windows (material ``shop_glass``) with a sign board each, blade signs
        and, for some buildings, awnings on the front's ground floor; balconies (slab and railing)
        on the upper floors of the front and back for some buildings; window surrounds
        (``facade_trim``) and rainwater pipes (``drainpipe``) at the corners of the front and back
        for some; flat roofs with a coping lip.
    """
    if facade not in FACADES:
        raise ValueError(f"facade must be one of {sorted(FACADES)}, got {facade!r}")
    if roof not in ROOFS:
        raise ValueError(f"roof must be one of {ROOFS}, got {roof!r}")
    if not (height >= 3.0 and floor_height >= 2.2):
        raise ValueError(f"height {height} m / floor_height {floor_height} m too small")
    poly = _clean(footprint)
    facade_mat = FACADES[facade]
    trim = draw_trim(substream(rng, "facade_trim"), facade)
    signs = substream(rng, "shop_signs")
    st = draw_style(rng, height, floor_height, facade)
    rect = rectangle_of(poly)
    if roof != "flat" and rect is None:
        log.debug("roof %r needs a rectangular footprint; using a flat roof", roof)
        roof = "flat"
    parapet = float(rng.uniform(0.6, 1.1)) if roof == "flat" else 0.0
    # a storey gets windows when its window top stays 0.55 m under the wall top; the parapet
    # is lowered to fit over the top row (rather than leaving the top storey blind)
    win_top = st.sill + min(st.win_h, floor_height - st.sill - 0.35)
    n_floors = max(1, int((height - 0.55 - win_top) // floor_height) + 1)
    if roof == "flat":
        parapet = min(parapet, height - (n_floors - 1) * floor_height - win_top - 0.15)

    k = len(poly)
    lengths = [float(np.linalg.norm(poly[(i + 1) % k] - poly[i])) for i in range(k)]
    # outward normal of edge i is (d_y, -d_x): the front edge has the most negative n_y = -d_x
    n_y = [round(-(poly[(i + 1) % k][0] - poly[i][0]) / lengths[i], 6) for i in range(k)]
    front = min(range(k), key=lambda i: (n_y[i], -lengths[i]))
    roles = ["front" if i == front else ("back" if n_y[i] > 0.99 else "side") for i in range(k)]
    door = {"width": float(rng.choice([1.1, 1.2, 1.8])), "height": float(rng.uniform(2.1, 2.4))}

    parts: list[Mesh] = []
    panes = []
    door_point = None
    for i in range(k):
        fc = _Facade(poly[i], poly[(i + 1) % k])
        d = dict(door) if i == front and fc.length >= 1.4 else None
        openings = holes(rng, fc.length, n_floors, floor_height, st, d, roles[i])
        for u0, u1, v0, v1 in wall_rects(fc.length, height, openings):
            fc.rect(u0, u1, v0, v1, 0.0, facade_mat)
        for h in openings:
            centre = _opening(fc, h, st, facade_mat, trim.surround)
            if h.kind == "door":
                door_point = fc.pts([((h.u0 + h.u1) / 2, 0.0, 0.0)])
            else:
                panes.append(centre)
            if h.kind == "balcony":
                balcony(fc, h, st, facade_mat)
        shop_front(fc, [h for h in openings if h.kind == "shop"], st, fc.length, rng, signs)
        if roles[i] != "side":
            parts += pipes(fc, trim.pipes_front if i == front else trim.pipe_back, height - 0.1)
        parts += fc.meshes()
    if roof == "flat":
        parts.append(flat_roof(rng, poly, height, parapet, facade_mat,
                               "facade_concrete" if facade in ("concrete", "glass") else "facade_trim"))
    else:
        parts.append(pitched_roof(rng, rect, height, roof, facade_mat))
    out = merge(parts)
    out.anchors = {"windows": np.array(panes).reshape(-1, 3)}
    if door_point is not None:
        out.anchors["door"] = door_point
    return out
