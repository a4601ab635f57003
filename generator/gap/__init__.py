"""``urbangen gap``: seed 002 §3.2's differences between LiDAR datasets, as curves and distances.

* :mod:`generator.gap.sources` -- reading datasets (SemanticKITTI layout; the seam for others);
* :mod:`generator.gap.rings` -- ring and column of each point from its position and the calibration;
* :mod:`generator.gap.objects` -- objects and their point counts (boxes through one adapter, or instances);
* :mod:`generator.gap.profile` -- one dataset measured into histograms;
* :mod:`generator.gap.measure` -- a dataset read through the ring fit into a profile;
* :mod:`generator.gap.distances` -- total variation and Wasserstein-1;
* :mod:`generator.gap.report`, :mod:`generator.gap.text`, :mod:`generator.gap.plots` -- gap.json, gap.md, charts.
"""
