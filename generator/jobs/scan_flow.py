"""The scene-flow side file of each scan, written as a sequence is cast (:mod:`generator.motion.scene_flow`).

A sweep's flow needs the next sweep (its flag says whether that sweep sees the point), so the
sequence writer hands every sweep's processed points to :meth:`ScanFlowWriter.add` as they come
and the writer files the previous sweep's ``scene_flow/NNNNNN.bin``
(:mod:`generator.formats.scene_flow`). The last sweep of a sequence gets none.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from generator.errors import UserError
from generator.formats.point_sidecars import TIMES_DIR, read_sidecar
from generator.formats.scene_flow import FOLDER, write_scene_flow
from generator.motion.scene_flow import SceneFlow


class ScanFlowWriter:
    """Writes ``seq_dir/scene_flow/`` for consecutive sweeps.

    Parameters
    ----------
    seq_dir : Path
        ``sequences/NN``.
    rig : generator.world.rig.Rig
        With the sequence's drive.
    world : generator.world.actors.World or None
        The actors (None: a frozen drive).
    sensor : generator.lidar.sensors.Sensor
    motion_skew : bool
        Whether the sweeps were cast with motion skew.
    """

    def __init__(self, seq_dir: Path, rig, world, sensor, motion_skew: bool):
        self.seq_dir = Path(seq_dir)
        self.rig, self.sensor, self.skew = rig, sensor, motion_skew
        self.actors = list(world.actors) if world is not None else []
        self.prototypes = world.prototypes if world is not None else None
        self._flows: SceneFlow | None = None
        self._prev: tuple[int, float, np.ndarray] | None = None

    def close(self) -> None:
        """Stop the scene flow's helper thread."""
        if self._flows is not None:
            self._flows.close()

    def __enter__(self) -> ScanFlowWriter:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def add(self, j: int, t_j: float, points: np.ndarray) -> None:
        """Sweep ``j`` (start ``t_j`` seconds; its processed point records, the ``.bin`` rows) is cast:
        write sweep ``j - 1``'s scene flow if that was the sweep before."""
        prev, self._prev = self._prev, (j, t_j, points)
        if prev is None or prev[0] != j - 1:
            return
        if self._flows is None:
            self._flows = SceneFlow.for_rig(self.rig, self.actors, self.sensor, self.skew, t_j - prev[1],
                                            prototypes=self.prototypes)
        obj, flag = self._flows.sweep(prev[2], points, prev[1])
        write_scene_flow(self.seq_dir, f"{prev[0]:06d}", obj, flag)


def remove_last(seq_dir: Path, n_sweeps: int) -> list[Path]:
    """Remove scene-flow files of sweeps ``>= n_sweeps - 1`` (an earlier, longer run's): the last sweep has none."""
    gone = []
    for p in sorted((Path(seq_dir) / FOLDER).glob("*.bin")):
        if p.stem.isdigit() and int(p.stem) >= n_sweeps - 1:
            p.unlink()
            gone.append(p)
    return gone


def write_sequence_flow(seq, out_dir: Path, rig, world, sensor, motion_skew: bool) -> int:
    """Scene flow of an existing sequence's scans, from its files (``urbangen flow``).

    Parameters
    ----------
    seq : generator.formats.semantickitti.Sequence
        With ``point_times/`` when cast with motion skew (the firing column of each point).
    out_dir : Path
        Where ``scene_flow/`` goes (the sequence folder, or a stage in its layout).
    rig, world, sensor, motion_skew
        As for :class:`ScanFlowWriter`; ``rig`` and ``world`` rebuilt from the spec.

    Returns
    -------
    int
        Scans written.
    """
    frames = sorted(seq.frames)
    with ScanFlowWriter(out_dir, rig, world, sensor, motion_skew) as writer:
        for j in frames:
            t_j = float(seq.times[j]) if seq.times is not None and j < len(seq.times) else rig.sweep_time(j)
            writer.add(j, t_j, _points(seq, j, sensor, motion_skew))
    return max(0, len(frames) - 1)


def _points(seq, j: int, sensor, motion_skew: bool) -> dict[str, np.ndarray]:
    """The fields of scan ``j`` the scene flow reads, from its files (the column from the firing time)."""
    rec = seq.read(j, True)
    n = len(rec.points)
    tau = read_sidecar(seq.dir, TIMES_DIR, j, n) if motion_skew else None
    if motion_skew and tau is None:
        raise UserError(f"{seq.dir / TIMES_DIR}: no firing times of scan {j:06d}: a sequence cast with motion "
                        "skew needs them for its scene flow")
    col = (np.zeros(n, np.int64) if tau is None else
           np.rint(np.asarray(tau, np.float64) * sensor.azimuth_steps * sensor.rotation_hz).astype(np.int64))
    inst = rec.instance if rec.instance is not None else np.zeros(n, np.uint16)
    return {"x": rec.points[:, 0], "y": rec.points[:, 1], "z": rec.points[:, 2], "instance": inst,
            "column": np.clip(col, 0, sensor.azimuth_steps - 1)}
