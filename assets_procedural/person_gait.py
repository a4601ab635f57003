"""A walking person's legs and arms through one gait cycle (unit body height, facing +x).

The cycle's phase ``phi`` in [0, 1) is a function of the distance walked (``phi = distance / stride``,
:mod:`generator.world.actors`), so the feet are planted, not sliding: over the stance half of its cycle
(``phi`` in [0, 0.5) for the leading leg) a foot moves backward in the body frame at a constant rate,
from ``+X`` to ``-X``, as far as the body walks forward over that half cycle; over the swing half it is
carried forward again, lifted clear of the ground. So the stride (two steps, one full cycle) is
``4 X`` with ``X = LEG_REACH * leg * sin(A)`` for the hip's swing amplitude ``A`` (20-25 degrees, about
0.72-0.8 of body height, as measured for adults at their preferred pace). The knees follow from the
legs' reach (two-link inverse kinematics): nearly straight in stance, bent about 60 degrees early in
the swing; the foot rolls over the heel at heel strike and onto the toes at push-off, and the pelvis
rides highest over the planted foot (a few centimetres of vertical bob). The arms swing opposite the
leg of their side, the elbow bending more as the arm comes forward.

Standing (``phi`` None): legs straight under the hips, feet flat.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from assets_procedural.parts import two_link

#: thigh and shin lengths, ankle above the sole, shoe toe and heel (from the ankle), unit body height
THIGH, SHIN, ANKLE_Z = 0.245, 0.25, 0.05
TOE_X, HEEL_X = 0.115, -0.045
LEG = THIGH + SHIN
HIP_Z = ANKLE_Z + LEG                   #: standing hip height
LEG_REACH = 0.995                       #: hip-ankle distance of a planted leg / leg length (knee a little soft)
LIFT = 0.045                            #: swing foot clearance at mid-swing
ARM_SHARE = 0.8                         #: arm swing amplitude / hip swing amplitude
HEEL_STRIKE, PUSH_OFF = np.radians(-12.0), np.radians(28.0)   #: foot pitch (+ = toe down) at those instants


def _bump(phi: float, centre: float, width: float) -> float:
    """Periodic Gaussian bump (period 1) of height 1 at ``centre``."""
    d = (phi - centre + 0.5) % 1.0 - 0.5
    return float(np.exp(-0.5 * (d / width) ** 2))


@dataclass(frozen=True)
class LegPose:
    """One leg at one instant, body frame of unit height (x forward, z up, sole plane z = 0).

    Attributes
    ----------
    hip, knee, ankle : (3,) float64
    pitch : float
        Foot pitch, radians (+ = toe down).
    """

    hip: np.ndarray
    knee: np.ndarray
    ankle: np.ndarray
    pitch: float


def foot_x(phi: float, half_step: float) -> float:
    """Ankle x (body frame) of a leg at its own phase ``phi``: linear back over stance, eased forward in swing."""
    phi = phi % 1.0
    if phi < 0.5:
        return half_step * (1.0 - 4.0 * phi)
    return -half_step * float(np.cos(2.0 * np.pi * (phi - 0.5)))


def foot_pitch(phi: float) -> float:
    """Foot pitch (radians, + = toe down) of a leg at its own phase: heel strike, flat, push-off, swing."""
    phi = phi % 1.0
    return HEEL_STRIKE * _bump(phi, 0.0, 0.04) + PUSH_OFF * _bump(phi, 0.53, 0.05)


def _ankle_lift(pitch: float) -> float:
    """Ankle height that keeps the lowest point of a foot pitched by ``pitch`` on the ground."""
    c, s = np.cos(pitch), np.sin(pitch)
    return max(x * s + ANKLE_Z * c for x in (TOE_X, HEEL_X))     # -(z of sole corner x after the pitch)


def legs(phi: float | None, amplitude: float, hip_y: float) -> tuple[list[LegPose], float]:
    """Both legs (side +1 = left first, then -1) and the pelvis height.

    Parameters
    ----------
    phi : float or None
        Gait phase of the left leg (the right one is half a cycle on); None stands.
    amplitude : float
        Hip swing amplitude, radians.
    hip_y : float
        Half the distance between the hip joints.

    Returns
    -------
    (legs, hip_z) : list of LegPose, float
    """
    if phi is None:
        out = [LegPose(np.array([0.0, s * hip_y, HIP_Z]), np.array([0.005, s * hip_y, ANKLE_Z + SHIN]),
                       np.array([0.0, s * hip_y, ANKLE_Z]), 0.0) for s in (1.0, -1.0)]
        return out, HIP_Z
    X = half_step(amplitude)
    targets = []
    for k in (0.0, 0.5):
        p = (phi + k) % 1.0
        pitch = foot_pitch(p)
        z = _ankle_lift(pitch) + (LIFT * np.sin(np.pi * (p - 0.5) / 0.5) ** 2 if p >= 0.5 else 0.0)
        targets.append((foot_x(p, X), z, pitch))
    reach = LEG_REACH * LEG
    hip_z = min(z + np.sqrt(max(reach ** 2 - x ** 2, 0.0)) for x, z, _ in targets)
    out = []
    for s, (x, z, pitch) in zip((1.0, -1.0), targets, strict=True):
        hip = np.array([0.0, s * hip_y, hip_z])
        knee, ankle = two_link(hip, np.array([x, s * hip_y, z]), THIGH, SHIN, np.array([1.0, 0.0, 0.0]))
        out.append(LegPose(hip, knee, ankle, pitch))
    return out, hip_z


def half_step(amplitude: float) -> float:
    """``X``: how far ahead of (and behind) the hip a planted foot lands (and leaves), unit height."""
    return LEG_REACH * LEG * float(np.sin(amplitude))


def stride(amplitude: float) -> float:
    """Distance walked over one gait cycle (two steps), unit body height."""
    return 4.0 * half_step(amplitude)


def arm_angle(phi: float | None, amplitude: float, side: float) -> float:
    """Upper-arm swing (radians, + = forward) of the arm on ``side`` (+1 left): opposite its leg."""
    if phi is None:
        return 0.0
    X = half_step(amplitude)
    p = phi if side > 0 else phi + 0.5
    return -ARM_SHARE * amplitude * foot_x(p, X) / X
