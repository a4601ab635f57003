"""Dataset file formats: SemanticKITTI, KITTI calib, PLY, label configs."""
