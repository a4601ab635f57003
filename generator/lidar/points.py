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
mixed           uint8   1 where the return merges sub-rays of different surfaces (physical returns)
echo            uint8   0 = the beam's strongest return, 1 = its second (dual mode)
power           float32 normalised received power of the return (0 with the ideal sensor)
=============== ======= ==========================================================

With the physical return model (:mod:`generator.lidar.returns`) the records are written by
:func:`generator.lidar.return_kernels.beam_returns` instead, the same fields.

How the records are filled: :meth:`RecordTables.fill` runs one compiled pass over a chunk's
hits (:func:`generator.lidar.kernels.fill_records`) from tables built once per scanner: the
sensor's local rays and per-ray azimuth, the firing offset per column, ring and laser per
position within a column, and one :data:`generator.lidar.kernels.FACE_DTYPE` row per face
(normal and labels, so a hit reads one row). The values are the float32 operations of a
field-by-field numpy fill (``x = o + r * d``; ``cos = |d0 n0 + d1 n1 + d2 n2|`` in that order).
"""

from __future__ import annotations

import numpy as np

from generator.lidar.kernels import FACE_DTYPE, fill_records

POINT_DTYPE = np.dtype([
    ("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("range", "<f4"), ("azimuth", "<f4"), ("time", "<f4"),
    ("cos_incidence", "<f4"), ("ring", "u1"), ("column", "<u2"), ("laser", "u1"), ("class", "u1"),
    ("instance", "<u2"), ("material", "<u2"), ("moving", "u1"), ("mixed", "u1"), ("echo", "u1"), ("power", "<f4"),
])


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
        #: (steps, L, 3) float32 emission points and unit directions, sensor frame, ring order
        self.origins = np.ascontiguousarray(origins, np.float32)
        self.directions = np.ascontiguousarray(dirs, np.float32)
        self._o, self._d = self.origins.reshape(-1, 3), self.directions.reshape(-1, 3)  # views, sweep ray order
        self._azimuth = np.ascontiguousarray(azimuth.reshape(-1), np.float32)
        self._column_time = np.ascontiguousarray(sensor.column_time(), np.float32)
        order = sensor.by_ring
        self._ring = np.ascontiguousarray(sensor.ring[order], np.uint8)
        self._laser = np.ascontiguousarray(sensor.laser_id[order], np.uint8)
        faces = np.zeros(len(face_class), FACE_DTYPE)
        faces["normal"], faces["class"] = normals, face_class
        faces["instance"], faces["material"] = face_instance, face_material
        self._faces = faces

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
            Face-table row of each hit (-1 on a miss; misses are never in ``hit``).
        direction : (n, 3) float32
            Beam direction in the frame of the hit face's normal (world for the town, the
            actor's frame for an actor: the cosine is the same in either).
        skew : bool
            Fill ``time`` with the firing offsets (else 0).
        """
        fill_records(out, np.ascontiguousarray(hit, np.int64), ray0, dist, np.ascontiguousarray(face, np.int32),
                     np.ascontiguousarray(direction, np.float32), self._o, self._d, self._azimuth,
                     self._column_time, self._ring, self._laser, self._faces, skew)
