"""Detection labels from the world in time: 3D boxes per sweep for every thing, visibility per image.

* :mod:`.subjects` -- :class:`Subject`, a boxed thing for the whole sequence (parked statics and
  actors; a ridden two-wheeler is one subject holding vehicle and rider), :func:`subjects`;
* :mod:`.records` -- :class:`BoxRecord`, one subject's box in one sweep (:func:`sweep_boxes`,
  :func:`boxes_at`), with ``num_lidar_pts`` from the sweep's labels;
* :mod:`.frames` -- boxes in LiDAR, ego, camera and world frames.

Pure numpy: nothing here reads or writes files.
"""

from generator.detection.records import BoxRecord, SweepClock, boxes_at, instance_counts, sweep_boxes
from generator.detection.subjects import Subject, subjects

__all__ = ["BoxRecord", "Subject", "SweepClock", "boxes_at", "instance_counts", "subjects", "sweep_boxes"]
