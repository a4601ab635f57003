"""Procedural town layout (pure numpy): streets, lots, placements, routes and frames."""
