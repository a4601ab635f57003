"""LiDAR remission: per-class profiles (:mod:`.class_profiles`), intensity models
(:mod:`.models`: constant, class-normal, physical, hybrid) and fitting a profile to a
dataset (:mod:`.fit`). Pure numpy; the LiDAR scan pipeline calls the models.
"""
