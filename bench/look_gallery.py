"""Render looks in Blender: crops of one town, and before/after sheets of two runs.

    python bench/look_gallery.py render OUT_DIR [--spec scenes/default_town.json] [--code-root TREE]
                                 [--size 640x360] [--samples 12] [--only ground horizon trees facades road]
    python bench/look_gallery.py compare BEFORE_DIR AFTER_DIR OUT_DIR
    python bench/look_gallery.py time --baseline MAIN_CHECKOUT [--frames 3] [--rounds 2] [--config preview|paper]
                                      [--lighting day night]

``render`` writes one PNG per shot into ``OUT_DIR`` (``<shot>.png``, RGB only) and ``sheet.png``
(RGB beside the label view, one row per shot), and prints the render seconds of every shot beside
the Blender scene build time measured in the same run. ``--code-root`` renders with another checkout
of urbangen (e.g. main, for the "before" crops); the default is the tree this script lies in.
``compare`` pastes the crops of two ``render`` runs side by side (``<shot>.png``: before | after)
and into one ``before_after.png``. ``time`` renders the same ego views (day and night) at the full
``preview`` preset with a baseline checkout and with this tree, interleaved, each in its own process, and
prints seconds per frame and each process's peak memory side by side (``--config paper`` for the paper
preset; ``--lighting day`` for day views only).

Shots, all in the town the spec builds (the spec's seed; day: sun at 38 degrees, clear; night: 40 %
lit windows):

* ``ground``  -- the road close up beside the kerb (dry, and soaked), the sidewalk, grass, the road
  from 14 m above (issue 29 item 2);
* ``horizon`` -- from the outer ring road's corner and from its middle, looking out of town, by day
  and by night (issue 29 item 6);
* ``trees``   -- a tree of each species in the town, the camera 1.6 m up, 1.6 crown heights away;
* ``facades`` -- the buildings with shop fronts and balconies, seen from the sidewalk across the street;
* ``road``    -- stretches of road seen from 2.2 m up, looking down the lane;
* ``facades_close`` -- a building of each wall material (render, brick, panels) from 8 m, and the
  first by night (issue 29 item 5);
* ``cars``    -- a parked car from the sidewalk, front three-quarter by day and by night, rear
  three-quarter and its tail (rear plate) from 2.6 m by day, and side-on through its windows by day
  (issue 29 item 3);
* ``people``  -- two walkers on a sidewalk, side on, at four gait phases each (the camera follows them), and a
  cyclist and a motorcyclist on their two-wheelers, side on (issue 29 item 4).

Render settings: the ``preview`` preset (OpenImageDenoise) at ``--size`` and ``--samples``, motion blur
and the camera model off (the crops are compared as scene radiance through one fixed tone map).
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

ROOT = Path(__file__).resolve().parents[1]
DAY = ("day", 38.0, 135.0)


def look_at(eye, target) -> np.ndarray:
    """(4, 4) optical-frame pose (x right, y down, z forward) at ``eye`` looking at ``target``."""
    eye, target = np.asarray(eye, float), np.asarray(target, float)
    z = target - eye
    z /= np.linalg.norm(z)
    x = np.cross(z, [0.0, 0.0, 1.0])
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = x, y, z, eye
    return T


GROUND_KINDS = ("street", "intersection", "sidewalk", "corner", "lot_ground", "terrain", "horizon")


@dataclasses.dataclass
class Shot:
    """One crop: a name (file stem), a title, a camera pose, the time of day and wetness."""

    name: str
    title: str
    pose: np.ndarray
    time_of_day: str = "day"
    wetness: float = 0.0
    time: float = 0.0          #: seconds on the world's timeline (the people block's walkers)


def _materials_of(scene, obj) -> set[str]:
    from generator.materials import material_table
    names = [r.name for r in material_table().rows]
    return {names[i] for i in np.unique(scene.prototypes[obj.prototype].face_material)}


def _clear_eye(scene, eye, target, reach: float = 3.0, skip=None) -> bool:
    """True when nothing of the town (but ``skip``) stands within 0.6 m of the camera or ``reach`` m
    along the first stretch of its sight line (object boxes, 2D)."""
    for o in scene.objects:
        if o is skip or o.kind in GROUND_KINDS or o.box is None or o.box.center[2] - o.box.size[2] / 2 > 2.0:
            continue
        c, size = np.asarray(o.box.center[:2]), np.asarray(o.box.size[:2])
        cs, sn = np.cos(o.box.yaw), np.sin(o.box.yaw)
        for t in np.linspace(0.0, reach, 7):
            p = eye[:2] + (target[:2] - eye[:2]) / np.linalg.norm(target[:2] - eye[:2]) * t
            d = p - c
            lx, ly = abs(d[0] * cs + d[1] * sn), abs(-d[0] * sn + d[1] * cs)
            if lx < size[0] / 2 + 0.6 and ly < size[1] / 2 + 0.6:
                return False
    return True


def tree_shots(scene) -> list[Shot]:
    """One shot per species found in the town (species told apart by their materials and shape)."""
    shots, seen = [], set()
    for o in scene.objects:
        if o.kind != "tree":
            continue
        mats = _materials_of(scene, o)
        m = scene.prototypes[o.prototype]
        ext = m.bounds()[1] - m.bounds()[0]
        species = ("conifer" if "needles" in mats else "birch" if "bark_birch" in mats
                   else "broad crown" if ext[0] > 0.75 * ext[2] else "upright / young")
        if species in seen:
            continue
        base = o.transform[:3, 3]
        h = float(ext[2])
        for ang in np.linspace(0, 2 * np.pi, 12, endpoint=False):
            eye = base + [np.cos(ang) * 1.5 * h, np.sin(ang) * 1.5 * h, 1.6]
            target = base + [0.0, 0.0, 0.5 * h]
            if _clear_eye(scene, eye, target):
                shots.append(Shot(f"tree_{species.split()[0]}", f"tree: {species}, {h:.1f} m", look_at(eye, target)))
                seen.add(species)
                break
    return shots + _foliage_shots(scene)


def _foliage_shots(scene) -> list[Shot]:
    """The first broad street tree from 5 m (looking up into the crown) and from 30 m, the first hedge
    from 3 m and the first bush from 2.5 m (issue 29 item 1: leaves, gaps, bark)."""
    shots = []
    wanted = (("tree", 5.0, 1.6, 0.55, "tree_at_5m"), ("tree", 30.0, 1.6, 0.45, "tree_at_30m"),
              ("hedge", 3.0, 1.4, 0.5, "hedge"), ("bush", 2.5, 1.2, 0.45, "bush"))
    for kind, dist, eye_z, aim, name in wanted:
        for o in scene.objects:
            if o.kind != kind:
                continue
            lo, hi = scene.prototypes[o.prototype].bounds()
            if kind == "tree" and hi[2] < 7.0:
                continue
            base = o.transform[:3, 3]
            target = base + [0.0, 0.0, aim * hi[2]]
            found = False
            for ang in np.linspace(0, 2 * np.pi, 16, endpoint=False):
                side = o.transform[:3, :3] @ np.array([0.0, 1.0, 0.0]) if kind == "hedge" else np.zeros(3)
                d = side * np.sign(np.cos(ang)) if kind == "hedge" else np.array([np.cos(ang), np.sin(ang), 0.0])
                eye = base + d * dist + [0.0, 0.0, eye_z]
                if _clear_eye(scene, eye, target, reach=min(3.0, dist - 1.0), skip=o):
                    shots.append(Shot(name, f"{kind} from {dist:g} m", look_at(eye, target)))
                    found = True
                    break
            if found:
                break
    return shots


def facade_shots(scene) -> list[Shot]:
    """Buildings with shop fronts (awnings), balconies and curtain walls, from across the street."""
    shots = []
    for want in ("awning", "balcony_metal", "facade_glass"):
        for o in scene.objects:
            if o.kind != "building" or want not in _materials_of(scene, o):
                continue
            T = o.transform
            lo, hi = scene.prototypes[o.prototype].bounds()
            front = T[:3, :3] @ np.array([0.0, -1.0, 0.0])
            centre = T[:3, :3] @ np.array([(lo[0] + hi[0]) / 2, lo[1], 0.0]) + T[:3, 3]
            eye = centre + front * 22.0 + T[:3, :3] @ np.array([6.0, 0.0, 0.0])
            eye[2] = T[2, 3] + 1.7
            target = centre + [0.0, 0.0, min(hi[2] * 0.35, 8.0)]
            if _clear_eye(scene, eye, target):
                shots.append(Shot(f"facade_{want}", f"facade: {o.attrs.get('facade')} with {want.replace('_', ' ')}",
                                  look_at(eye, target)))
                break
    return shots


# -- issue 29 item 5 (facades helper): close facade crops, kept apart from the shots above ---------


def facade_close_shots(scene) -> list[Shot]:
    """A building of each wall material from the sidewalk opposite its front corner, ~9 m away, 1.7 m
    up (bricks, render, panels, trim, pipes and shop signs at the scale a driving camera sees them
    close); the first one again by night."""
    shots = []
    for want in ("plaster", "brick", "concrete"):
        for o in scene.objects:
            if o.kind != "building" or o.attrs.get("facade") != want:
                continue
            T = o.transform
            lo, hi = scene.prototypes[o.prototype].bounds()
            front = T[:3, :3] @ np.array([0.0, -1.0, 0.0])
            corner = T[:3, :3] @ np.array([lo[0] + 1.5, lo[1], 0.0]) + T[:3, 3]
            eye = corner + front * 8.0 + T[:3, :3] @ np.array([-3.0, 0.0, 0.0])
            eye[2] = T[2, 3] + 1.7
            target = corner + T[:3, :3] @ np.array([3.0, 0.0, 0.0]) + [0.0, 0.0, 3.5]
            if _clear_eye(scene, eye, target, 6.0):
                shots.append(Shot(f"facade_close_{want}", f"facade close: {want}, 8 m", look_at(eye, target)))
                break
    if shots:
        shots.append(dataclasses.replace(shots[0], name=shots[0].name + "_night", time_of_day="night",
                                         title=shots[0].title + ", night"))
    return shots


# -- end of the facades helper's block -------------------------------------------------------------


def road_shots(scene) -> list[Shot]:
    path = max(scene.paths, key=lambda p: p.length())
    out = []
    for k, (s, ahead) in enumerate(((0.18, 14.0), (0.55, 14.0), (0.33, 6.0), (0.8, 6.0))):
        (p,), (hd,) = path.at(s * path.length())
        d = np.array([np.cos(hd), np.sin(hd), 0.0])
        out.append(Shot(f"road_{k}", f"road: {path.name} at {s * path.length():.0f} m",
                        look_at(p + [0.0, 0.0, 2.2], p + d * ahead)))
    return out


def _segment_point(seg_T: np.ndarray, u: float, v: float, z: float) -> np.ndarray:
    return seg_T[:3, :3] @ np.array([u, v, 0.0]) + seg_T[:3, 3] + [0.0, 0.0, z]


def ground_shots(town) -> list[Shot]:
    """Road beside the kerb (dry and wet), the sidewalk, grass, the road from above (issue 29 item 2).

    Streets are found in the scene (object kind ``street``, segment frame: u along, v across); the
    camera stands over the carriageway 1 m off the kerb, or on the sidewalk, where nothing blocks it.
    """
    grid = town.grid
    rh, wi, ch = grid.road_half, grid.walk_inner, grid.corridor_half
    shots = []
    streets = [o for o in town.objects if o.kind == "street"]
    streets.sort(key=lambda o: -np.asarray(o.box.size)[:2].max())
    for o in streets:
        T, L = o.transform, float(np.asarray(o.box.size)[:2].max())
        eye = _segment_point(T, 0.35 * L, -(rh - 1.2), 1.5)
        target = _segment_point(T, 0.35 * L + 5.0, -(rh - 0.3), 0.0)
        if _clear_eye(town, eye, target, 5.0):
            shots.append(Shot("road_closeup", "road close-up by the kerb, 1.5 m up", look_at(eye, target)))
            shots.append(Shot("road_closeup_wet", "road close-up by the kerb, wet (0.9)", look_at(eye, target),
                              wetness=0.9))
            break
    for o in streets:
        T, L = o.transform, float(np.asarray(o.box.size)[:2].max())
        eye = _segment_point(T, 0.6 * L, (wi + ch) / 2, grid.curb_h + 1.6)
        target = _segment_point(T, 0.6 * L + 6.0, (wi + ch) / 2 - 0.3, grid.curb_h)
        if _clear_eye(town, eye, target, 6.0):
            shots.append(Shot("sidewalk", "sidewalk, 1.6 m up", look_at(eye, target)))
            break
    grass = [o for o in town.objects if o.kind == "lot_ground" and o.cls == "terrain"]
    grass += [o for o in town.objects if o.kind == "terrain"]
    for o in grass:
        c = np.asarray(o.box.center)
        eye = np.array([c[0], c[1], grid.curb_h + 1.6])
        for ang in np.linspace(0, 2 * np.pi, 8, endpoint=False):
            target = eye + [4.0 * np.cos(ang), 4.0 * np.sin(ang), -1.6]
            if _clear_eye(town, eye, target, 4.0):
                shots.append(Shot("grass", f"grass ({o.kind}), 1.6 m up", look_at(eye, target)))
                break
        if shots[-1].name == "grass":
            break
    path = max(town.paths, key=lambda p: p.length())
    (p,), (hd,) = path.at(0.4 * path.length())
    d = np.array([np.cos(hd), np.sin(hd), 0.0])
    shots.append(Shot("road_above", "road from 14 m above", look_at(p + [0.0, 0.0, 14.0] - 0.5 * d, p + d * 1.0)))
    return shots


def horizon_shots(town) -> list[Shot]:
    """Out of town from the outer ring road: its south-west corner looking south-west, the middle of
    its south side looking south-south-east; each by day and by night (issue 29 item 6)."""
    grid = town.grid
    x0, y0, x1, y1 = grid.corridor_rect
    c = grid.corridor_half
    corner = np.array([x0 + c, y0 + c, 1.65])
    mid = np.array([(x0 + x1) / 2 + 3.0, y0 + c - 1.5, 1.65])
    views = [("corner", corner, corner + [-40.0, -40.0, 3.0]), ("south", mid, mid + [15.0, -40.0, 3.5])]
    shots = []
    for name, eye, target in views:
        for tod in ("day", "night"):
            shots.append(Shot(f"horizon_{name}_{tod}", f"horizon from the ring road's {name}, {tod}",
                              look_at(eye, target), time_of_day=tod))
    return shots


# -- cars (issue 29 item 3, helper "cars") -------------------------------------------------------------
def car_shots(town) -> list[Shot]:
    """A parked car close up from the sidewalk, front three-quarter view, 1.6 m up, by day and by night; the
    rear three-quarter view and its tail (the rear plate) from 2.6 m by day; and the same car side-on through
    its windows (issue 29 item 3)."""
    for o in town.objects:
        if o.cls != "car" or o.attrs.get("placement") != "parked":
            continue
        T = o.transform
        lo, hi = town.prototypes[o.prototype].bounds()
        centre = T[:3, :3] @ np.array([(lo[0] + hi[0]) / 2, 0.0, 0.9]) + T[:3, 3]
        for side in (1.0, -1.0):
            eye = T[:3, :3] @ np.array([hi[0] + 1.6, side * (hi[1] + 2.6), 1.6]) + T[:3, 3]
            eye_side = T[:3, :3] @ np.array([(lo[0] + hi[0]) / 2 - 0.3, side * (hi[1] + 2.8), 1.5]) + T[:3, 3]
            if _clear_eye(town, eye, centre, 2.0) and _clear_eye(town, eye_side, centre, 2.0):
                eye_rear = T[:3, :3] @ np.array([lo[0] - 1.6, side * (hi[1] + 2.6), 1.6]) + T[:3, 3]
                eye_tail = T[:3, :3] @ np.array([lo[0] - 2.6, side * 0.9, 1.1]) + T[:3, 3]
                tail = T[:3, :3] @ np.array([lo[0], 0.0, 0.7]) + T[:3, 3]
                return [Shot("car_day", "car: parked, front three-quarter, day", look_at(eye, centre)),
                        Shot("car_rear_day", "car: parked, rear three-quarter, day", look_at(eye_rear, centre)),
                        Shot("car_tail_day", "car: parked, its tail from 2.6 m, day", look_at(eye_tail, tail)),
                        Shot("car_night", "car: parked, front three-quarter, night", look_at(eye, centre),
                             time_of_day="night"),
                        Shot("car_side_day", "car: parked, side-on through the windows, day",
                             look_at(eye_side, centre))]
    return []
# -- end of cars ---------------------------------------------------------------------------------------


# -- people (issue 29 item 4): a walker through its gait, riders on their two-wheelers ------------------------------
# A separate block: the shots need a world (the walker is an actor, posed by the timeline), so they are rendered by
# a Renderer of their own (:func:`render_people`). With a checkout whose actors have no gait (main before the
# people branch) the same walker is drawn as that checkout draws it: its one walking pose, moved along.

PEOPLE_PHASES = (0, 2, 4, 6)      #: gait phases (of 16) shown side on: both feet down, ..., feet passing


def people_world(town, spec):
    """(world, shots): two walkers of the town's library on a sidewalk, each seen side on at
    :data:`PEOPLE_PHASES` (the camera follows it), and a cyclist and a motorcyclist on their two-wheelers
    (built for the shots), side on."""
    from generator.layout.placement.appearance import outfit
    from generator.layout.placement.variety import person_variants
    from generator.world.actors import Actor, Track, World

    try:                                    # this tree: walkers with their gait cycle
        from generator.traffic.pedestrians.gait import gait_cycle
        from generator.world.actors import Gait
    except ImportError:                     # an older checkout: one pose
        gait_cycle = Gait = None
    grid = town.grid
    streets = sorted((o for o in town.objects if o.kind == "street"), key=lambda o: -np.asarray(o.box.size)[:2].max())
    v_walk = (grid.walk_inner + grid.corridor_half) / 2
    walking = person_variants(town.library, spec)[len(person_variants(town.library, spec)) // 2:]
    base = 1 + max(o.instance_id for o in town.objects)
    protos, actors, shots = {}, [], []
    speed, dt = 1.4, 0.05
    spots = [(o, u, sv) for o in streets for sv in (1.0, -1.0) for u in np.linspace(0.12, 0.8, 18)
             if _people_clear(town, o, u, sv * v_walk, grid.curb_h)]
    spots = [spots[0]] + [x for x in spots if x[0] is not spots[0][0]][:1] if spots else []
    for i, ((o, u, sv), proto) in enumerate(zip(spots, (walking[0], walking[-1]), strict=False)):
        T, L = o.transform, float(np.asarray(o.box.size)[:2].max())
        start = _segment_point(T, u * L, sv * v_walk, grid.curb_h)
        d = T[:3, :3] @ np.array([sv, 0.0, 0.0])
        ts = np.arange(0.0, 10.0, dt)
        track = Track(0.0, dt, start[None] + ts[:, None] * speed * d[None], np.full(len(ts), np.arctan2(d[1], d[0])))
        key = f"walker_{i}"
        protos[key] = proto.mesh
        lo, hi = np.asarray(proto.lo), np.asarray(proto.hi)
        extra = {}
        stride = 0.75 * float(hi[2])
        if gait_cycle is not None:
            keys, stride, plo, phi = gait_cycle(key, proto.mesh, protos)
            extra = {"gait": Gait(keys, stride, Gait.walked(track), plo, phi)}
            lo, hi = plo.min(0), phi.max(0)
        actors.append(Actor(i, f"actor_person_{i:04d}", "person", "person", base + i, key, tuple(hi - lo),
                            tuple((lo + hi) / 2), track, None, {**outfit(np.random.default_rng(5 + i)),
                                                                "role": "walking"}, **extra))
        across = T[:3, :3] @ np.array([0.0, -sv, 0.0])        # from the carriageway side
        t_zero = np.ceil(2.0 * speed / stride) * stride / speed  # walked a whole number of strides: phase 0
        for k in PEOPLE_PHASES:
            t = t_zero + (k / 16) * stride / speed
            p = track.position(t)[0]
            eye = p + across * 3.2 + [0.0, 0.0, 1.0]
            shots.append(Shot(f"people_walker{i}_phase{k:02d}", f"walker {i} ({proto.params.get('height', 0):.2f} m),"
                              f" gait phase {k}/16", look_at(eye, p + [0.0, 0.0, 0.85]), time=t))
        if i == 0:      # closer looks at mid-swing: 4 m side on, 4 m and 10 m three-quarter from ahead
            t = t_zero + (4 / 16) * stride / speed
            p = track.position(t)[0]
            for name, dist, ahead in (("side4m", 4.0, 0.0), ("front34_4m", 4.0, 1.0), ("front34_10m", 10.0, 1.0)):
                eye = p + (across + d * ahead) / np.hypot(1.0, ahead) * dist + [0.0, 0.0, 1.5]
                shots.append(Shot(f"people_walker0_{name}", f"walker 0, {name}", look_at(eye, p + [0.0, 0.0, 0.9]),
                                  time=t))
    # a cyclist and a motorcyclist on their two-wheelers, standing on the carriageway of the first street
    from assets_procedural.riders import ridden
    from generator.geometry import merge
    from generator.layout.placement.appearance import fleet_paint

    T, L = streets[0].transform, float(np.asarray(streets[0].box.size)[:2].max())
    d = T[:3, :3] @ np.array([1.0, 0.0, 0.0])
    for j, kind in enumerate(("bicyclist", "motorcyclist")):
        rider, vehicle = ridden(kind, np.random.default_rng(11 + j))
        key = f"ridden_{kind}"
        protos[key] = merge([rider, vehicle])
        lo, hi = protos[key].bounds()
        c = _segment_point(T, (0.55 + 0.15 * j) * L, -0.5 * grid.lane_half, 0.0)       # in the lane
        track = Track(0.0, dt, np.repeat(c[None], 3, 0), np.full(3, np.arctan2(d[1], d[0])))
        uid = len(actors)
        actors.append(Actor(uid, f"actor_{kind}_{uid:04d}", kind, kind, base + uid, key, tuple(hi - lo),
                            tuple((lo + hi) / 2), track, None, {**fleet_paint(np.random.default_rng(3 + j)),
                                                                **outfit(np.random.default_rng(9 + j)),
                                                                "role": "driving"}))
        sides = [c + (T[:3, :3] @ np.array([0.0, sgn, 0.0])) * 2.6 + [0.0, 0.0, 1.1] for sgn in (1.0, -1.0)]
        eye = next((e for e in sides if _clear_eye(town, e, c, 2.0)), sides[0])
        shots.append(Shot(f"people_{kind}", f"{kind} on its two-wheeler, side on", look_at(eye, c + [0.0, 0.0, 0.9]),
                          time=1.0))
    return World(town, actors, protos, {}, None, 10.0), shots


def _people_clear(town, street, u: float, v: float, z: float) -> bool:
    """Whether a walker starting at (``u`` of the street's length, ``v``) on its sidewalk can be seen side on
    from 3.2 m toward the carriageway over its first 4 m (nothing within 0.6 m of the camera or on the line)."""
    T, L = street.transform, float(np.asarray(street.box.size)[:2].max())
    for du in (2.0, 2.5, 3.0, 3.5, 4.0):
        p = _segment_point(T, u * L + np.sign(v) * du, v, z + 1.0)
        eye = _segment_point(T, u * L + np.sign(v) * du, v - np.sign(v) * 3.2, z + 1.0)
        if not _clear_eye(town, eye, p, 3.0):
            return False
    return True


def render_people(town, spec, cfg, tmp, out: Path) -> list:
    """Render :func:`people_world`'s shots (RGB and labels); return sheet rows as :func:`render` does."""
    from generator.blender.renderer import Renderer
    from generator.labels import class_table
    from generator.weather import Lighting

    world, shots = people_world(town, spec)
    r = Renderer(town, spec, cfg, Path(tmp) / "people", world)
    r.set_conditions(Lighting(*DAY))
    rows = []
    for shot in shots:
        r.set_time(shot.time)
        t0 = time.perf_counter()
        frame = r.render(shot.pose, spec.seed, {})
        print(f"{shot.title:48s} {time.perf_counter() - t0:6.1f} s")
        rgb = to_srgb(frame.rgb)
        Image.fromarray(rgb).save(out / f"{shot.name}.png")
        rows.append((shot.title, rgb, class_table().colors[frame.labels.class_id].astype(np.uint8)))
    return rows

# -- end of the people block -------------------------------------------------------------------------------------


def render(args) -> int:
    sys.path.insert(0, str(Path(args.code_root).resolve() if args.code_root else ROOT))
    import generator
    from generator.blender.renderer import Renderer
    from generator.labels import class_table
    from generator.layout import build_scene
    from generator.spec import load_spec
    from generator.spec.render import load_render_config
    from generator.weather import Lighting
    print(f"code: {Path(generator.__file__).parents[1]}")
    spec = load_spec(args.spec)
    t0 = time.perf_counter()
    town = build_scene(spec)
    t_layout = time.perf_counter() - t0
    w, h = (int(x) for x in args.size.split("x"))
    base = load_render_config("preview")
    cfg = dataclasses.replace(base, resolution=(w, h), samples=args.samples, camera_model=False,
                              motion_blur=dataclasses.replace(base.motion_blur, enabled=False))
    makers = {"ground": ground_shots, "horizon": horizon_shots, "trees": tree_shots, "facades": facade_shots,
              "road": road_shots, "facades_close": facade_close_shots, "cars": car_shots}
    shots = [s for key in args.only if key in makers for s in makers[key](town)
             if not args.shots or s.name in args.shots]
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        r = Renderer(town, spec, cfg, Path(tmp))
        t_build = time.perf_counter() - t0
        for shot in shots:
            light = Lighting(*DAY) if shot.time_of_day == "day" else Lighting("night", lit_windows=0.4)
            r.set_conditions(light, wetness=shot.wetness, puddle_seed=17.0)
            t0 = time.perf_counter()
            frame = r.render(shot.pose, spec.seed, {})
            secs = time.perf_counter() - t0
            present = [class_table().names[c] for c in np.unique(frame.labels.class_id)]
            print(f"{shot.title:48s} {secs:6.1f} s  classes: {', '.join(present)}")
            rgb = to_srgb(frame.rgb, night=shot.time_of_day == "night")
            Image.fromarray(rgb).save(out / f"{shot.name}.png")
            rows.append((shot.title, rgb, class_table().colors[frame.labels.class_id].astype(np.uint8)))
        if "people" in args.only:
            rows += render_people(town, spec, cfg, tmp, out)
    print(f"layout {t_layout:.1f} s, Blender scene build {t_build:.1f} s (baseline for the render seconds above); "
          f"{len(town.faces)} triangles")
    sheet = Image.new("RGB", (2 * w + 12, len(rows) * (h + 20) + 4), (240, 240, 240))
    draw = ImageDraw.Draw(sheet)
    for k, (title, rgb, lab) in enumerate(rows):
        y = k * (h + 20)
        draw.text((4, y + 4), title, fill=(0, 0, 0))
        sheet.paste(Image.fromarray(rgb), (4, y + 18))
        sheet.paste(Image.fromarray(lab), (w + 8, y + 18))
    sheet.save(out / "sheet.png")
    print(f"{len(rows)} shots -> {out}")
    return 0


def to_srgb(rgb: np.ndarray, night: bool = False) -> np.ndarray:
    """8-bit sRGB of scene-linear radiance: a fixed gentle tone map (night: 4 EV brighter, to see it)."""
    x = np.clip(rgb, 0, None) * (16.0 if night else 1.0)
    x = x / (1 + x)
    x = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)
    return (np.clip(x * 1.6, 0, 1) * 255).astype(np.uint8)


def compare(args) -> int:
    before, after, out = Path(args.before), Path(args.after), Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    names = [p.name for p in sorted(after.glob("*.png")) if p.name != "sheet.png" and (before / p.name).exists()]
    pairs = []
    for name in names:
        a, b = Image.open(before / name).convert("RGB"), Image.open(after / name).convert("RGB")
        w, h = a.size
        img = Image.new("RGB", (2 * w + 12, h + 20), (240, 240, 240))
        d = ImageDraw.Draw(img)
        d.text((4, 3), f"before: {name[:-4]}", fill=(0, 0, 0))
        d.text((w + 8, 3), "after", fill=(0, 0, 0))
        img.paste(a, (4, 18))
        img.paste(b, (w + 8, 18))
        img.save(out / name)
        pairs.append(img)
    if pairs:
        w, h = pairs[0].size
        sheet = Image.new("RGB", (w, h * len(pairs)), (240, 240, 240))
        for k, img in enumerate(pairs):
            sheet.paste(img, (0, k * h))
        sheet.save(out / "before_after.png")
    print(f"{len(pairs)} before/after pairs -> {out}")
    return 0


def drive_poses(town, n: int) -> list[np.ndarray]:
    """``n`` camera poses along the longest route, 1.65 m up, looking down the lane (ego-like)."""
    path = max(town.paths, key=lambda p: p.length())
    out = []
    for s in (np.arange(n) + 0.5) / n:
        (p,), (hd,) = path.at(s * path.length())
        d = np.array([np.cos(hd), np.sin(hd), 0.0])
        out.append(look_at(p + [0.0, 0.0, 1.65], p + d * 20.0 + [0.0, 0.0, 1.2]))
    return out


def time_one(args) -> int:
    """Render ``--frames`` ego views at the full ``--config`` preset (label pass, camera model, motion blur
    settings as the preset has them); print one JSON line of seconds and peak memory.

    Without ``--traffic`` the views are spread along the longest route of the static town; with it they
    are frames 0, 3, 6, ... of the spec's own drive, the town's traffic posed at each frame's time and
    the camera exposed as ``generate`` exposes it (moving cars, people, riders in view)."""
    import json
    import resource
    sys.path.insert(0, str(Path(args.code_root).resolve()))
    from generator.blender.renderer import Renderer
    from generator.layout import build_scene
    from generator.spec import load_spec
    from generator.spec.render import load_render_config
    from generator.weather import Lighting

    spec = load_spec(args.spec)
    town = build_scene(spec)
    cfg = load_render_config(args.config)
    world = poses = None
    if args.traffic:
        from generator.jobs.drive import MARGIN_M
        from generator.jobs.variants import pose_for
        from generator.traffic.build import build_world
        from generator.world.rig import Rig

        last = 3 * (args.frames - 1)
        world = build_world(spec, town, 0.0, last * spec.paths.spacing_m + MARGIN_M)
        rig = Rig.from_world(spec, world)
        poses = [rig.frame(k) for k in range(0, last + 1, 3)]
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        r = Renderer(town, spec, cfg, Path(tmp), world)
        build = time.perf_counter() - t0
        rows = []
        for tod in args.lighting:
            r.set_conditions(Lighting(*DAY) if tod == "day" else Lighting("night", lit_windows=0.4))
            if poses is None:
                seconds = [r.render(T, spec.seed, {}).seconds for T in drive_poses(town, args.frames)]
            else:
                seconds = []
                for frame in poses:
                    pose_for(r, frame, rig)()    # actors at the frame's time, the camera exposed around it
                    t1 = time.perf_counter()
                    _, rgb_s = r.render_rgb(spec.seed)
                    labels = r.render_labels()
                    seconds.append({"rgb_pass": rgb_s, **labels.seconds, "render_total": time.perf_counter() - t1})
            rows += [{k: round(v, 3) for k, v in secs.items()} for secs in seconds]
    use = resource.getrusage(resource.RUSAGE_SELF)
    print(json.dumps({"build": round(build, 3), "triangles": int(len(town.faces)), "frames": rows,
                      "max_rss_mb": round(use.ru_maxrss / 1024), "cpu_s": round(use.ru_utime + use.ru_stime, 1)}))
    return 0


def time_compare(args) -> int:
    """Main (``--baseline``) beside this tree, interleaved ``--rounds`` times in one run."""
    import json
    import subprocess
    trees = {"baseline": Path(args.baseline).resolve(), "this tree": ROOT}
    runs: dict[str, list] = {k: [] for k in trees}
    for _ in range(args.rounds):
        for name, tree in trees.items():
            cmd = [sys.executable, str(Path(__file__).resolve()), "_time_one", "--code-root", str(tree),
                   "--spec", str(args.spec), "--frames", str(args.frames), "--config", args.config,
                   "--lighting", *args.lighting, *(["--traffic"] if args.traffic else [])]
            out = subprocess.run(cmd, capture_output=True, text=True, check=True, cwd=tree)
            runs[name].append(json.loads(out.stdout.strip().splitlines()[-1]))
    views = "drive frames with traffic" if args.traffic else "ego views of the static town"
    print(f"{args.config} preset, {args.frames} {views} x ({', '.join(args.lighting)}) x {args.rounds} rounds, "
          f"{args.spec}")
    print(f"{'tree':12s} {'triangles':>10s} {'build s':>8s} {'rgb s/frame':>12s} {'labels s/frame':>15s} "
          f"{'total s/frame':>14s} {'peak MB':>8s} {'process CPU s':>14s}")
    total, parts = {}, {}
    for name, rs in runs.items():
        fr = [f for r in rs for f in r["frames"]]
        rgb = np.mean([f["rgb_pass"] for f in fr])
        tot = np.mean([f["render_total"] for f in fr])
        total[name], parts[name] = tot, (rgb, tot - rgb)
        print(f"{name:12s} {rs[0]['triangles']:10d} {np.mean([r['build'] for r in rs]):8.2f} {rgb:12.2f} "
              f"{tot - rgb:15.2f} {tot:14.2f} {max(r['max_rss_mb'] for r in rs):8d} "
              f"{np.mean([r.get('cpu_s', np.nan) for r in rs]):14.1f}")
    (rgb_b, lab_b), (rgb_t, lab_t) = parts["baseline"], parts["this tree"]
    print(f"ratio this tree / baseline: total per frame {total['this tree'] / total['baseline']:.3f}, "
          f"RGB {rgb_t / rgb_b:.3f}, label pass {lab_t / lab_b:.3f}")
    return 0


def _checkout(text: str) -> str:
    """An urbangen checkout (a folder holding ``generator/``), for ``--code-root`` / ``--baseline``."""
    if not (Path(text) / "generator" / "__init__.py").is_file():
        raise argparse.ArgumentTypeError(f"{text}: not an urbangen checkout (no generator/ package in it)")
    return text


def _folder(text: str) -> str:
    """An existing folder (the crops of a ``render`` run)."""
    if not Path(text).is_dir():
        raise argparse.ArgumentTypeError(f"{text}: no such folder")
    return text


def _positive(text: str) -> int:
    try:
        n = int(text)
    except ValueError:
        n = 0
    if n < 1:
        raise argparse.ArgumentTypeError(f"must be a whole number >= 1, got {text!r}")
    return n


def _spec_file(text: str) -> Path:
    if not Path(text).is_file():
        raise argparse.ArgumentTypeError(f"{text}: no such spec file")
    return Path(text)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("render", help="render the crops of one tree")
    r.add_argument("out", help="folder for the crops and sheet.png")
    r.add_argument("--spec", type=_spec_file, default=ROOT / "scenes" / "default_town.json")
    r.add_argument("--code-root", type=_checkout, default=None,
                   help="the urbangen checkout to render with (default: this one)")
    r.add_argument("--size", default="640x360", help="WIDTHxHEIGHT of every crop")
    r.add_argument("--samples", type=_positive, default=12, help="Cycles samples (denoised)")
    r.add_argument("--only", nargs="*", default=["ground", "horizon"],
                   choices=["ground", "horizon", "trees", "facades", "road", "facades_close", "cars", "people"])
    r.add_argument("--shots", nargs="*", default=None, help="render only these shots (file stems)")
    c = sub.add_parser("compare", help="before | after sheets of two render runs")
    c.add_argument("before", type=_folder)
    c.add_argument("after", type=_folder)
    c.add_argument("out")
    t = sub.add_parser("time", help="preview-preset render time of a baseline checkout beside this tree")
    t.add_argument("--baseline", type=_checkout, required=True, help="the checkout to compare with (e.g. main)")
    t.add_argument("--spec", type=_spec_file, default=ROOT / "scenes" / "default_town.json")
    t.add_argument("--frames", type=_positive, default=3)
    t.add_argument("--rounds", type=_positive, default=2)
    t.add_argument("--config", choices=["preview", "paper"], default="preview", help="render preset")
    t.add_argument("--lighting", nargs="+", choices=["day", "night"], default=["day", "night"])
    t.add_argument("--traffic", action="store_true",
                   help="the spec's own drive with its traffic (moving cars, people) instead of a static town")
    o = sub.add_parser("_time_one")
    o.add_argument("--code-root", required=True)
    o.add_argument("--spec", type=Path, required=True)
    o.add_argument("--frames", type=int, default=3)
    o.add_argument("--config", default="preview")
    o.add_argument("--lighting", nargs="+", default=["day", "night"])
    o.add_argument("--traffic", action="store_true")
    args = ap.parse_args(argv)
    return {"render": render, "compare": compare, "time": time_compare, "_time_one": time_one}[args.cmd](args)


if __name__ == "__main__":
    sys.exit(main())
