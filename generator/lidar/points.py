"""The point record of a sweep and the kernel that turns first hits into records.

Point record (:data:`POINT_DTYPE`, one structured row per return; no-return rays and rays
blocked nearer than the sensor's minimum range are not points):

=============== ======= ==========================================================
field           dtype   meaning
=============== ======= ==========================================================
x, y, z         float32 sensor frame at firing time, metres (x fwd, y left, z up)
range           float32 distance from the laser's emission point along the beam, metres
                        (what the device measures; differs from |xyz| by the offsets)
azimuth         float32 beam azimuth, radians CCW from +x, in [-pi, pi)
time            float32 firing offset after the sweep start, seconds (0 with skew off)
cos_incidence   float32 |dot(beam direction, face normal)|
ring            uint8   beam row by elevation, 0 = highest
column          uint16  firing column, 0 .. azimuth_steps - 1
laser           uint8   device laser id
class           uint8   native class id (``scene.face_class``; an actor's ``face_class``)
instance        uint16  instance id (``scene.face_instance``, 0 for stuff; ``actor.instance_id``)
material        uint16  material id (``scene.face_material``; an actor's ``face_material``)
moving          uint8   1 on an actor faster than ``MOVING_THRESHOLD_MPS`` at the firing time
=============== ======= ==========================================================

How the records are filled (:meth:`RecordTables.fill`): the fields are written in byte
blocks through :data:`_BLOCKS`, a second view of the same 38-byte record -- ``x, y, z, range``
as one 16-byte block (``o + r d`` computed over the chunk's contiguous (n, 4) rows whose 4th
column is ``(0, 1)``, so ``range`` comes out as ``r`` exactly, then gathered by hit),
``azimuth .. laser`` as one 16-byte block gathered from a per-ray template, ``class,
instance, material, moving`` as a 4-byte block (gathered with the face normal, one 16-byte
row per face) and a 2-byte block -- plus ``cos_incidence`` on its own. Compared with one strided write per field this halves the
numpy passes of the labelling, which is the scanner's only cost beyond the Embree cast
(``bench/lidar_traffic.py``). The values are the same float32 operations as a field-by-field
fill (``x = o + r * d``; ``cos = |d0 n0 + d1 n1 + d2 n2|`` in that order), so the bytes are too.
"""

from __future__ import annotations

import numpy as np

POINT_DTYPE = np.dtype([
    ("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("range", "<f4"), ("azimuth", "<f4"), ("time", "<f4"),
    ("cos_incidence", "<f4"), ("ring", "u1"), ("column", "<u2"), ("laser", "u1"), ("class", "u1"),
    ("instance", "<u2"), ("material", "<u2"), ("moving", "u1"),
])

#: The same record as byte blocks and the incidence cosine (see the module notes).
_BLOCKS = np.dtype({"names": ["xyzr", "ray", "cos", "face4", "face2"], "formats": ["V16", "V16", "<f4", "<u4", "<u2"],
                    "offsets": [0, 16, 24, 32, 36], "itemsize": POINT_DTYPE.itemsize})
_FACE = np.dtype([("class", "u1"), ("instance", "<u2"), ("material", "<u2"), ("moving", "u1")])


class RecordTables:
    """Everything a sweep's records are gathered from, built once per scanner.

    Parameters
    ----------
    sensor : generator.lidar.sensors.Sensor
    face_class, face_instance, face_material : (F,) integer
        Per face-table row (the town's faces, then each actor prototype's).
    normals : (F, 3) float32
        Unit face normals (world frame for the town, local frames for prototypes).
    """

    def __init__(self, sensor, face_class, face_instance, face_material, normals):
        origins, dirs, azimuth = sensor.local_rays()
        steps, n_l = azimuth.shape
        self._o4 = _rows4(origins.reshape(-1, 3), 0.0)  # (n_rays, 4) float32, sensor frame
        self._d4 = _rows4(dirs.reshape(-1, 3), 1.0)
        order = sensor.by_ring
        rec = np.zeros(steps * n_l, POINT_DTYPE)
        rec["azimuth"] = azimuth.reshape(-1)
        rec["ring"] = np.tile(sensor.ring[order], steps)
        rec["column"] = np.repeat(np.arange(steps), n_l)
        rec["laser"] = np.tile(sensor.laser_id[order], steps)
        self._ray = {False: np.ascontiguousarray(rec.view(_BLOCKS)["ray"])}
        rec["time"] = np.repeat(sensor.column_time(), n_l)
        self._ray[True] = np.ascontiguousarray(rec.view(_BLOCKS)["ray"])
        face = np.zeros(len(face_class), _FACE)
        face["class"], face["instance"], face["material"] = face_class, face_instance, face_material
        blocks = face.view(np.uint8).reshape(-1, 6)
        # per face one 16-byte row: unit normal (3 x float32) + class, instance, material's low byte,
        # so one gather serves the cosine and most of the label block; one zero row at the end: a
        # miss (face -1) reads it, so cosines can be computed for every ray of a chunk at once
        rows = np.zeros((len(face) + 1, 4), np.uint32)  # label bits never pass through a float
        rows.view(np.float32)[:-1, :3] = normals
        rows[:-1, 3] = np.ascontiguousarray(blocks[:, :4]).view("<u4").reshape(-1)
        self._normal_face4 = rows.view("V16").reshape(-1)
        self._face2 = np.ascontiguousarray(blocks[:, 4:]).view("<u2").reshape(-1)

    def fill(self, out: np.ndarray, hit: np.ndarray, ray0: int, dist: np.ndarray, face: np.ndarray,
             direction: np.ndarray, skew: bool) -> None:
        """Write the records of one chunk's hits into ``out``.

        Parameters
        ----------
        out : (h,) POINT_DTYPE
            Destination (a slice of the sweep's array; written in place).
        hit : (h,) int64
            The chunk's rays that are points, ascending.
        ray0 : int
            Sweep index of the chunk's first ray (its rays are contiguous).
        dist : (n,) float32
            Distance along each beam to its hit, metres.
        face : (n,) int
            Face-table row of each hit (-1 on a miss).
        direction : (n, 3) float32
            Beam direction in the frame of the hit face's normal (world for the town, the
            actor's frame for an actor: the cosine is the same in either).
        skew : bool
            Fill ``time`` with the firing offsets (else 0).
        """
        blocks = out.view(_BLOCKS)
        n = len(dist)
        with np.errstate(invalid="ignore"):  # misses (inf) times a zero component; dropped below
            xyzr = self._d4[ray0:ray0 + n] * dist[:, None]
        xyzr += self._o4[ray0:ray0 + n]
        blocks["xyzr"] = xyzr.view("V16").reshape(-1).take(hit)
        blocks["ray"] = self._ray[skew].take(hit + ray0)
        row = self._normal_face4.take(face).view(np.uint32).reshape(n, 4)
        normal = row.view(np.float32)
        cos = direction[:, 0] * normal[:, 0]
        cos += direction[:, 1] * normal[:, 1]
        cos += direction[:, 2] * normal[:, 2]
        blocks["cos"] = np.abs(cos, out=cos).take(hit)
        blocks["face4"] = np.ascontiguousarray(row[:, 3]).take(hit)
        blocks["face2"] = self._face2.take(face.take(hit))


def _rows4(xyz: np.ndarray, w: float) -> np.ndarray:
    out = np.empty((len(xyz), 4), np.float32)
    out[:, :3] = xyz
    out[:, 3] = w
    return out
