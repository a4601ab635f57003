"""Label sets: one native class table and the mappings derived from it, as data."""

from generator.labels.registry import ClassInfo, ClassTable, class_table

__all__ = ["ClassInfo", "ClassTable", "class_table"]
