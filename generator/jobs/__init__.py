"""Dataset jobs: planning, worker orchestration, per-image output."""
