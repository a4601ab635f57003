"""Motion of OpenLABEL objects: the cuboid, velocity, acceleration and moving flag at an instant.

Conventions (one for every object, static or actor):

* **Instant**: the sweep START ``t_j`` (``times.txt``, :meth:`generator.world.rig.Rig.sweep_time`).
  It is the instant of the frame's ego transform, of the camera exposure paired with the sweep,
  and of the cuboid; velocity and acceleration are taken at the same instant, so a cuboid and
  its velocity always describe one state. (Mid-sweep would match the average firing time of a
  scan, but then cuboids and the ego transform would be 0.05 s apart.)
* **Velocity and acceleration of the cuboid centre** over ground, as seed 002 writes them from
  CARLA's world-frame ``get_velocity``/``get_acceleration``: vectors expressed in the root
  ``odom`` frame (fixed to the ground, the vehicle frame of frame 0; ``coordinate_system`` says
  so on every vector), so they do not change when the ego turns and a parked car reads 0
  even when the ego drives past it. Rotate by the frame's ``vehicle-iso8855_to_odom``
  transform (inverse) for ego axes.
* **Differences**: central differences of the cuboid centre over ``+-h`` with ``h`` = the
  actor track's sample spacing (0.05 s): ``v = (c(t+h) - c(t-h)) / 2h``,
  ``a = (c(t+h) - 2 c(t) + c(t-h)) / h^2``. Positions are linear between track samples, so
  ``v`` is the mean velocity over ``[t-h, t+h]``; the finite difference of the cuboid
  centres of the neighbouring sweeps (``+-0.1 s``) is the mean over ``[t-0.1, t+0.1]``: the
  two agree within ``max|a| * 0.1 s`` (``tests/test_openlabel_motion.py``).
* **moving**: the actor's horizontal speed at ``t`` (of its track's reference point) is above
  :data:`generator.world.actors.MOVING_THRESHOLD_MPS` -- exactly the rule that gives its LiDAR
  points the SemanticKITTI moving-* ids (:meth:`generator.world.actors.World.moving`).
  Static town objects: zero vectors, ``moving`` false.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from generator.world.actors import MOVING_THRESHOLD_MPS

#: Names of the per-frame object data (``vec`` / ``num`` / ``boolean``).
VELOCITY, ACCELERATION = "velocity", "acceleration"
SPEED, ACCEL_NORM, MOVING = "speed", "acceleration_magnitude", "moving"


@dataclass(frozen=True)
class Motion:
    """One object's state at one instant (world frame).

    Attributes
    ----------
    box : generator.world.scene.OrientedBox
        World frame, metres.
    velocity : (3,) float64
        Velocity of the box centre, world frame, m/s.
    acceleration : (3,) float64
        Acceleration of the box centre, world frame, m/s^2.
    moving : bool
        Faster than :data:`MOVING_THRESHOLD_MPS` (the LiDAR moving-* rule).
    """

    box: object
    velocity: np.ndarray
    acceleration: np.ndarray
    moving: bool


def static_motion(box) -> Motion:
    """A static object's state: its box, zero velocity and acceleration, not moving."""
    return Motion(box, np.zeros(3), np.zeros(3), False)


def actor_motion(actor, t: float, h: float | None = None) -> Motion:
    """An actor's state at time ``t`` (seconds on the world timeline).

    Parameters
    ----------
    actor : generator.world.actors.Actor
    t : float
        Seconds.
    h : float, optional
        Difference step, seconds (default: the track's sample spacing).
    """
    h = actor.track.dt if h is None else float(h)
    c = [np.asarray(actor.box(t + d).center, np.float64) for d in (-h, 0.0, h)]
    v = (c[2] - c[0]) / (2 * h)
    a = (c[2] - 2 * c[1] + c[0]) / (h * h)
    moving = bool(actor.track.speed(t)[0] > MOVING_THRESHOLD_MPS)
    return Motion(actor.box(t), v, a, moving)


def motion_data(m: Motion, R_odom_world: np.ndarray, cs: str) -> dict:
    """OpenLABEL ``object_data`` entries (``vec``, ``num``, ``boolean``) of a state.

    Parameters
    ----------
    m : Motion
    R_odom_world : (3, 3) float64
        Rotation world -> ``cs`` (vectors only rotate).
    cs : str
        Name of the coordinate system the vectors are expressed in.
    """
    v = R_odom_world @ m.velocity
    a = R_odom_world @ m.acceleration
    r = lambda x: [float(e) for e in np.round(x, 6)]  # noqa: E731
    return {
        "vec": [{"name": VELOCITY, "val": r(v), "coordinate_system": cs, "type": "values"},
                {"name": ACCELERATION, "val": r(a), "coordinate_system": cs, "type": "values"}],
        "num": [{"name": SPEED, "type": "value", "val": round(float(np.linalg.norm(v)), 6)},
                {"name": ACCEL_NORM, "type": "value", "val": round(float(np.linalg.norm(a)), 6)}],
        "boolean": [{"name": MOVING, "type": "value", "val": bool(m.moving)}],
    }


def object_data(obj_data: dict, name: str, kind: str):
    """The entry ``name`` of type ``kind`` (``"vec"``, ``"num"``, ``"boolean"``, ``"cuboid"``) of an
    object's per-frame ``object_data``, or ``None``."""
    for d in obj_data.get(kind, []):
        if d.get("name") == name:
            return d
    return None
