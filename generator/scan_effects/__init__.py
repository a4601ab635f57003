"""What happens to a scan's points after the cast: the effects chain
(:mod:`.pipeline`: intensity model -> domain gap -> LiDAR weather), seed 002's domain-gap
processing (:mod:`.domain_gap`) and the LiDAR weather tied to the image weather
(:mod:`.weather`). Pure numpy, shared by urbangen's own scans and imported datasets.
"""
