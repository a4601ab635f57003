"""Spec variants of the LiDAR for tests that need exact geometry.

The hdl64e preset casts the physical sensor (range noise, mixed points on edges, dropped weak returns).
Tests that check geometry to the millimetre (points on their faces, boxes holding every point, depth equal
to range) cast the ideal sensor: every ray's first hit.
"""

from __future__ import annotations

import dataclasses


def with_lidar(spec, **fields):
    """``spec`` with ``sensors.lidar`` fields replaced (``returns="ideal"``, ``motion_skew=False`` ...)."""
    lidar = dataclasses.replace(spec.sensors.lidar, **fields)
    return dataclasses.replace(spec, sensors=dataclasses.replace(spec.sensors, lidar=lidar))


def ideal(spec):
    """``spec`` casting the ideal sensor (``sensors.lidar.returns = "ideal"``)."""
    return with_lidar(spec, returns="ideal")
