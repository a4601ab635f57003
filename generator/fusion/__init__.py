"""Camera-LiDAR fusion (seed 001): project labelled LiDAR points into the rendered images.

* :mod:`generator.fusion.projection` -- Eq. 1 (``d [u v 1]^T = K T X``), motion de-skew,
  the occlusion test against the rendered depth, 1-pixel mask boundaries.
* :mod:`generator.fusion.agreement` -- projected image labels vs ray-cast labels: confusion
  matrices and per-class IoU for every variant (occlusion, proxies, boundaries).
* :mod:`generator.fusion.semantic_map` -- Eq. 2 (``pose @ point``): a sequence accumulated
  in one frame, voxel-downsampled with the majority label, PLY + top-down PNG.
* :mod:`generator.fusion.dataset` -- reading a dataset folder's images and scans frame by frame.
"""
