"""Image outputs: previews, post effects, EXR and metadata."""
