"""Image post-processing in numpy, after the render: fog (:mod:`.fog`), rain (:mod:`.rain`)
and the filters they share (:mod:`.filters`). RGB only: masks and depth are never touched.
"""
