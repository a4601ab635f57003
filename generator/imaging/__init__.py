"""Image files: the multilayer EXR (RGB, masks, depth, instances) and the metadata JSON."""
