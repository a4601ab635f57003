"""Lots: blocks (and the band outside the outer ring road) cut into lots, each with its plan, and the
districts that set the plans.

Modules import downward only: ``districts``, ``outskirts`` (the lot band's rows), then ``lot``
(:class:`~generator.layout.lots.lot.Lot`, :func:`~generator.layout.lots.lot.make_lots`).
"""

from generator.layout.lots.lot import Lot, make_lots

__all__ = ["Lot", "make_lots"]
