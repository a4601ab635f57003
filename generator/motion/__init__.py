"""Motion ground truth, exact from the world in time: optical flow, stereo disparity, LiDAR scene flow.

Pure numpy (and numba kernels); no renders, no ray casts. Every quantity comes from passes and
poses a dataset already has: the depth pass (distance along each pixel-centre ray), the
instance pass and the LiDAR labels (which actor a surface belongs to), the camera and LiDAR
poses of the rig, and the actors' rigid poses as functions of time
(:mod:`generator.world.kinematics`).

* :mod:`.optical_flow` -- per-pixel flow from one image to another of the same camera stream,
  with the masks ``KNOWN`` (the surface point and its position at the other time are known),
  ``VISIBLE`` (it is in frame and not occluded there) and ``ACTOR`` (it moves with an actor);
* :mod:`.owners` -- which actor the surface seen by a pixel belongs to;
* :mod:`.disparity` -- stereo disparity ``d = f b / Z`` of a rectified pair with the right
  view's occlusion;
* :mod:`.scene_flow` -- per LiDAR point the displacement of its surface to the next sweep,
  with and without the ego's motion, and whether the next sweep can see it.
"""
