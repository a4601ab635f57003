"""Image post-processing in numpy, after the render: fog (:mod:`.fog`), rain (:mod:`.rain`),
the filters they share (:mod:`.filters`) and then the camera that records the result
(:mod:`.camera`, :mod:`.camera_crf`). RGB only: masks and depth are never touched.
"""
