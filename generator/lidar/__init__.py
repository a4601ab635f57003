"""Virtual spinning LiDAR: sensor tables, Embree ray casting against the SceneModel, labelled points."""
