"""Helpers shared by the tests (never a test module: tests import kits, not each other)."""
