"""A 10 Hz LiDAR sequence through moving traffic: every method on the same rays, in one run.

    python bench/lidar_traffic.py [--traffic lanes|sim] [--actors 120] [--sweeps 20] [--rounds 5]

The default town (``scenes/default_town.json``) with a traffic block (the shipped densities x3,
the most its lanes hold), then one of two worlds:

* ``lanes`` (default): ``--actors`` car / truck prototypes of the town's asset library driving
  the scene's lane loops at 8-14 m/s (tracks sampled every 0.05 s), so every one of them moves
  all the time; the ego drives route 0 at the spec's speed among them (:func:`lane_world`).
* ``sim``: :func:`generator.traffic.build.build_world` (IDM car-following, signals): ~150
  vehicles of which about a third move at any instant; the ego is the simulated one.

Rows, on the rays of the same HDL-64E sweeps (2083 x 64 = 133,312 rays each, motion skew on):

* raw casts on the already-transformed float32 rays through each backend (Embree called directly,
  :mod:`generator.lidar.embree_native`, and embreex's ``run(output=1)``), 1 and 2 threads
  (contiguous chunks, as many as the scanner's), against the static town and against the town
  with every actor frozen into it at the first sweep's start (the same triangles, no motion);
* ours: ``Scanner.scan`` -- rays -> labelled points -- static town only, then with the world's
  actors moving through every sweep (:mod:`generator.lidar.actors`), 1 and 2 threads;
* the physical sensor (:mod:`generator.lidar.returns`) with the actors moving, 2 threads, one ray per
  beam, built up a step at a time: the power test only (received power against the threshold; no
  glass pass, no range noise), + the glass pass (rays go on behind panes), + range noise (= the
  preset without divergence, "received power only"); then the preset itself (strongest return with
  beam divergence) and dual returns with beam divergence; and both again with the divergence model as it
  was before ``edge_subrays: differing`` (every sub-ray of a split beam cast: "all sub-rays").
  The ideal scanner and the two divergence rows run once more through embreex's ``run``
  ("embreex" rows: the backend before Embree was called directly, whose watertight triangle test gives the
  same points up to float rounding).

* the ideal scanner and both divergence modes once more as one stream of the same sweeps, each submitted
  (:meth:`generator.lidar.scan.Scanner.submit`) before the one before it is read, as ``urbangen lidar``
  casts a sequence: no thread waits at a sweep boundary (the best of the rounds' whole-stream times).

Timings: each sweep of each method is timed in each of ``--rounds`` interleaved rounds and the
best time per sweep is kept (a burst of load from other processes spoils one sample, not a row);
CPU seconds per sweep are printed as well (load-independent).
"""

from __future__ import annotations

import argparse
import dataclasses
import itertools
import json
import os
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from generator.jobs.lidar_returns import return_model  # noqa: E402
from generator.layout.assemble import build_scene  # noqa: E402
from generator.lidar.caster import EmbreeCaster  # noqa: E402
from generator.lidar.scan import Scanner  # noqa: E402
from generator.lidar.sensors import sensor_for_spec, with_returns  # noqa: E402
from generator.spec import parse_spec  # noqa: E402
from generator.world.actors import Actor, Track, World  # noqa: E402
from generator.world.rig import SWEEP_PERIOD_S, Rig  # noqa: E402

#: the returns block of the divergence model as it was before only the differing sub-rays were cast
ALL_SUBRAYS = {"edge_subrays": "all"}
TRAFFIC_X3 = {"cars_per_km": 36, "trucks_per_km": 3, "buses_per_km": 1.5, "cyclists_per_km": 6,
              "motorcyclists_per_km": 3}


def lane_world(spec, scene, n: int, duration_s: float, ego_s: float) -> World:
    """``n`` vehicles on the scene's lane loops at 8-14 m/s.

    On the ego's route (0) nobody is within 10 m of the ego at t = 0 (arc length ``ego_s``), and the
    vehicles within 80 m drive at the ego's speed, so none runs into it during the sequence.
    """
    from generator.layout.placement.prototypes import Library

    g = np.random.default_rng(spec.seed)
    lib = Library(spec.seed)
    t = np.arange(int(np.ceil(duration_s / 0.05)) + 3) * 0.05
    protos, actors = {}, []
    paths = [p for p in scene.paths if p.closed]
    ends = np.cumsum([p.length() for p in paths])
    for s in g.permutation(np.linspace(0.0, ends[-1], 4 * n, endpoint=False)):
        if len(actors) == n:
            break
        i = int(np.searchsorted(ends, s, side="right"))
        path, s0 = paths[i], s - (ends[i - 1] if i else 0.0)
        gap = abs((s0 - ego_s + path.length() / 2) % path.length() - path.length() / 2) if i == 0 else np.inf
        if gap < 10.0:
            continue
        speed = spec.paths.speed_mps if gap < 80.0 else g.uniform(8.0, 14.0)
        kind = "truck" if len(actors) % 8 == 7 else "car"
        proto = lib.variant(kind, len(actors) % 6)
        protos[proto.key] = proto.mesh
        pos, head = path.at(s0 + speed * t)
        lo, hi = proto.lo, proto.hi
        actors.append(Actor(len(actors), f"actor_{kind}_{len(actors):04d}", kind, kind, 60000 + len(actors), proto.key,
                            tuple(hi - lo), tuple((hi + lo) / 2), Track(0.0, 0.05, pos, np.unwrap(head))))
    return World(scene, actors, protos, {}, None, duration_s)


def sweep_rays(sensor, poses: np.ndarray, center: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(n, 3) float32 re-centred origins and directions of one skewed sweep, as the scanner casts them."""
    o_l, d_l, _ = sensor.local_rays()
    rot_t = np.swapaxes(poses[:, :3, :3], -1, -2).astype(np.float32)
    d = np.matmul(d_l.astype(np.float32), rot_t)
    o = np.matmul(o_l.astype(np.float32), rot_t) + (poses[:, :3, 3] - center).astype(np.float32)[:, None]
    return np.ascontiguousarray(o.reshape(-1, 3)), np.ascontiguousarray(d.reshape(-1, 3))


def frozen_caster(scene, world: World, t: float, center: np.ndarray, town: bool = True) -> EmbreeCaster:
    """One BVH of the town (or nothing) plus every actor posed at ``t`` (what re-posing per time slice builds)."""
    verts, faces = ([scene.vertices.astype(np.float64)], [scene.faces.astype(np.int64)]) if town else ([], [])
    off = len(scene.vertices) if town else 0
    for a in world.actors:
        m, T = world.prototypes[a.prototype], a.track.pose(t)[0]
        verts.append(m.vertices @ T[:3, :3].T + T[:3, 3])
        faces.append(m.faces + off)
        off += len(m.vertices)
    return EmbreeCaster(np.concatenate(verts), np.concatenate(faces), center=center)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--spec", default=str(ROOT / "scenes" / "default_town.json"))
    ap.add_argument("--traffic", choices=("lanes", "sim"), default="lanes")
    ap.add_argument("--actors", type=int, default=120, help="vehicles of the lanes world")
    ap.add_argument("--sweeps", type=int, default=20)
    ap.add_argument("--t0", type=float, default=1.0, help="first sweep start, seconds")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--threads", type=int, default=2)
    args = ap.parse_args(argv)

    doc = json.loads(Path(args.spec).read_text())
    doc["traffic"] = dict(TRAFFIC_X3)
    spec = parse_spec(doc, args.spec)
    t = time.perf_counter()
    scene = build_scene(spec)
    print(f"scene {spec.name} (traffic densities x3): {len(scene.faces):,} triangles, {time.perf_counter() - t:.1f} s; "
          f"machine: {os.cpu_count()} cores shared with other processes")
    sensor = sensor_for_spec(spec)
    times = args.t0 + np.arange(args.sweeps) * SWEEP_PERIOD_S
    duration = float(times[-1]) + 1.0
    t = time.perf_counter()
    if args.traffic == "sim":
        from generator.traffic.build import build_world

        world = build_world(spec, scene, duration)
        rig = Rig.from_world(spec, world)
    else:
        rig = Rig.from_spec(spec, scene)
        world = lane_world(spec, scene, args.actors, duration, 0.0)  # the ego starts route 0 at t = 0
    moving = np.mean([world.moving(float(x)).sum() for x in times])
    print(f"world ({args.traffic}): {len(world.actors)} actors, {moving:.0f} moving on average over the sequence, "
          f"{len(world.prototypes)} prototypes, {sum(m.n_faces for m in world.prototypes.values()):,} prototype "
          f"triangles, built in {time.perf_counter() - t:.1f} s")

    poses = [rig.sweep_poses(float(x), sensor.column_time()) for x in times]
    static = EmbreeCaster.from_scene(scene)
    t = time.perf_counter()
    static_x = EmbreeCaster(scene.vertices, scene.faces, native=False)
    build_x = time.perf_counter() - t
    t = time.perf_counter()
    frozen = frozen_caster(scene, world, float(times[0]), static.center)
    build_frozen = time.perf_counter() - t
    t = time.perf_counter()
    frozen_caster(scene, world, float(times[0]), static.center, town=False)
    build_posed = time.perf_counter() - t
    rays = [sweep_rays(sensor, p, static.center) for p in poses]
    n_chunks = args.threads * 4
    pool = ThreadPoolExecutor(args.threads)

    def raw(caster, threads):
        def run(i):
            o, d = rays[i]
            if threads == 1:
                caster.run_raw(o, d)
                return
            edges = np.linspace(0, sensor.azimuth_steps, n_chunks + 1).round().astype(int) * sensor.n_lasers
            list(pool.map(lambda od: caster.run_raw(*od), [(o[a:b], d[a:b]) for a, b in itertools.pairwise(edges)]))
        return run

    t = time.perf_counter()
    for m in world.prototypes.values():
        EmbreeCaster(m.vertices, m.faces, center=np.zeros(3))
    build_protos = time.perf_counter() - t
    scanners = {(w, th): Scanner(scene, sensor, threads=th, caster=static, world=world if w else None)
                for w in (False, True) for th in (1, args.threads)}
    methods = {
        ("raw embree, static town", 1): raw(static, 1),
        ("raw embree, static town", args.threads): raw(static, args.threads),
        ("raw embreex, static town", 1): raw(static_x, 1),
        ("raw embreex, static town", args.threads): raw(static_x, args.threads),
        ("raw embree, town + actors frozen", 1): raw(frozen, 1),
        ("raw embree, town + actors frozen", args.threads): raw(frozen, args.threads),
    }
    for (w, th), sc in list(scanners.items()):
        name = "ours: Scanner.scan, actors moving" if w else "ours: Scanner.scan, static town"
        methods[(name, th)] = lambda i, sc=sc: sc.scan(poses[i], t0=float(times[i]))
    scanners["x"] = Scanner(scene, sensor, threads=args.threads, caster=static_x, world=world)
    methods[("embreex: Scanner.scan, actors moving", args.threads)] = \
        lambda i: scanners["x"].scan(poses[i], t0=float(times[i]))
    physical = {}
    # the physical rows: (label, return mode, overrides of the preset's returns block)
    for label, mode, over in (("physical: power test only", "strongest",
                               {"subrays": 1, "glass_layers": 0, "range_noise_m": 0.0}),
                              ("physical: power + glass", "strongest", {"subrays": 1, "range_noise_m": 0.0}),
                              ("physical: received power only", "strongest", {"subrays": 1}),
                              ("physical: strongest + divergence", "strongest", {}),
                              ("physical: dual + divergence", "dual", {}),
                              # the divergence model before edge_subrays: every sub-ray of a split beam cast
                              ("physical: strongest + divergence, all sub-rays", "strongest", ALL_SUBRAYS),
                              ("physical: dual + divergence, all sub-rays", "dual", ALL_SUBRAYS),
                              ("embreex: strongest + divergence", "strongest", {}),
                              ("embreex: dual + divergence", "dual", {})):
        s_mode = with_returns(sensor, mode)
        s_mode = dataclasses.replace(s_mode, returns=dataclasses.replace(s_mode.returns, **over))
        sc = Scanner(scene, s_mode, threads=args.threads, caster=static_x if label.startswith("embreex") else static,
                     world=world, returns=return_model(s_mode, spec.seed))
        physical[label] = sc
        scanners[(label, args.threads)] = sc
        methods[(label, args.threads)] = lambda i, sc=sc: sc.scan(poses[i], t0=float(times[i]), noise_key=i)
    # best of the rounds for every sweep on its own: a burst of load from other processes spoils one
    # sweep of one method, not a whole row
    best = {k: np.full((2, args.sweeps), np.inf) for k in methods}
    streamed = {("ours: Scanner.scan, actors moving", args.threads): scanners[(True, args.threads)],
                **{(k, args.threads): physical[k] for k in ("physical: strongest + divergence",
                                                            "physical: dual + divergence")}}
    seq_best = dict.fromkeys(streamed, np.inf)

    def stream(sc):  # as `urbangen lidar` casts a sequence (generator.jobs.lidar_sequence)
        for _ in sc.stream(args.sweeps, lambda i: sc.submit(poses[i], t0=float(times[i]), noise_key=i)):
            pass
    for _ in range(args.rounds):
        for k, fn in methods.items():
            for i in range(args.sweeps):
                c0, w0 = time.process_time(), time.perf_counter()
                fn(i)
                wall, cpu = time.perf_counter() - w0, time.process_time() - c0
                best[k][:, i] = np.minimum(best[k][:, i], (wall, cpu))
            if k in streamed:  # the same sweeps in one stream, the next submitted before this one is read
                w0 = time.perf_counter()
                stream(streamed[k])
                seq_best[k] = min(seq_best[k], time.perf_counter() - w0)
    best = {k: tuple(v.sum(1)) for k, v in best.items()}
    scans = [scanners[(True, args.threads)].scan(p, t0=float(x)) for p, x in zip(poses, times, strict=False)]
    kept = {k: np.mean([len(sc.scan(p, t0=float(x), noise_key=i).points)
                        for i, (p, x) in enumerate(zip(poses, times, strict=True))]) for k, sc in physical.items()}
    for sc in scanners.values():
        sc.close()
    pool.shutdown()

    n = args.sweeps
    print(f"\n{args.sweeps} sweeps of {sensor.rays_per_sweep:,} rays at 10 Hz from t = {args.t0} s, "
          f"{args.rounds} rounds\n")
    print(f"{'method':44s} {'thr':>3s} {'rays/s':>12s} {'sweeps/s':>9s} {'ms/sweep':>9s} {'CPU ms/sweep':>13s}")
    for (name, th), (wall, cpu) in best.items():
        print(f"{name:44s} {th:3d} {sensor.rays_per_sweep * n / wall:12,.0f} {n / wall:9.1f} {1000 * wall / n:9.2f} "
              f"{1000 * cpu / n:13.2f}")
    raw_s = best[("raw embree, static town", args.threads)]
    ours_s = best[("ours: Scanner.scan, static town", args.threads)]
    ours_a = best[("ours: Scanner.scan, actors moving", args.threads)]
    raw_f = best[("raw embree, town + actors frozen", args.threads)]
    cpu = {k: v[1] for k, v in best.items()}
    cpu_static, cpu_moving = cpu[("ours: Scanner.scan, static town", 1)], cpu[("ours: Scanner.scan, actors moving", 1)]
    print(f"\nstatic: ours / raw embree, {args.threads} threads: {raw_s[0] / ours_s[0]:.2f}x (target >= 0.95x); "
          f"CPU per sweep, raw / ours, 1 thread: {cpu[('raw embree, static town', 1)] / cpu_static:.2f}x")
    x_s = best[("raw embreex, static town", args.threads)]
    print(f"backends: Embree called directly / embreex run, raw casts on {args.threads} threads: "
          f"{x_s[0] / raw_s[0]:.2f}x faster; town BVH build {build_x / static.build_seconds:.2f}x faster "
          f"({static.build_seconds:.2f} s against {build_x:.2f} s)")
    print(f"moving actors: ours {n / ours_a[0]:.1f} sweeps/s = "
          f"{sensor.rays_per_sweep * n / ours_a[0] / 1e6:.2f} M rays/s "
          f"on {args.threads} threads (target >= 30 sweeps/s, 4 M rays/s); "
          f"{raw_f[0] / ours_a[0]:.2f}x raw embree on the "
          f"town with the actors frozen; CPU over static-only: "
          f"+{1000 * (cpu_moving - cpu_static) / n:.2f} ms/sweep")
    on_actor = np.array([(s.points["instance"] >= 60000).sum() if args.traffic == "lanes" else
                         np.isin(s.points["instance"], [a.instance_id for a in world.actors]).sum() for s in scans])
    mov = np.array([s.points["moving"].sum() for s in scans])
    plan = [
        scanners[(True, 1)].actors.plan(p, float(x), sensor.column_time()) for p, x in zip(poses, times, strict=False)
    ]
    cand = [0 if pl is None else int(np.clip(pl.ring1 - pl.ring0, 0, None).sum()) for pl in plan]
    seen = [0 if pl is None else len(np.unique(pl.actor)) for pl in plan]
    base = best[("ours: Scanner.scan, actors moving", args.threads)][0]
    # issue #27 on its machine: ideal at 5.3x real time, divergence >= 2x real time (<= 2.65x ideal's time),
    # received power <= +5 %; judged here as ratios to the ideal scanner in the same run
    ratio_target = {"physical: received power only": 1.05, "physical: power test only": 1.05,
                    "physical: power + glass": 1.05}
    for k in physical:
        w = best[(k, args.threads)][0]
        ideal_pts = np.mean([len(s.points) for s in scans])
        print(f"{k}: {n / w:.1f} sweeps/s = {n / w / sensor.rotation_hz:.2f}x the real sensor's "
              f"{sensor.rotation_hz:.0f} Hz, {w / base:.2f}x the ideal scanner's time "
              f"(target <= {ratio_target.get(k, 2.65):.2f}x); "
              f"{kept[k]:,.0f} points per sweep ({100 * kept[k] / sensor.rays_per_sweep:.1f} % of the rays; "
              f"ideal {ideal_pts:,.0f})")
    print(f"ideal, actors moving: {n / base:.1f} sweeps/s = {n / base / sensor.rotation_hz:.2f}x real time")
    for k in ("ideal", "strongest + divergence", "dual + divergence"):
        new = best[("ours: Scanner.scan, actors moving", args.threads)] if k == "ideal" else best[(f"physical: {k}",
                                                                                                    args.threads)]
        old = best[("embreex: Scanner.scan, actors moving", args.threads)] if k == "ideal" else best[(f"embreex: {k}",
                                                                                                    args.threads)]
        print(f"{k}, actors moving: {n / new[0] / sensor.rotation_hz:.2f}x real time (embreex run: "
              f"{n / old[0] / sensor.rotation_hz:.2f}x), {old[0] / new[0]:.2f}x faster")
    for k in streamed:
        one = best[k][0]
        label = "ideal" if k[0].startswith("ours") else k[0][len("physical: "):]
        print(f"{label}, actors moving, one stream of {n} sweeps (each submitted before the one before is read): "
              f"{n / seq_best[k] / sensor.rotation_hz:.2f}x real time "
              f"(sweeps one at a time: {n / one / sensor.rotation_hz:.2f}x)")
    print(f"per sweep: {np.mean(seen):.0f} actors in range, {np.mean(cand):,.0f} rays in their column windows (before "
          f"the per-laser azimuth and static-distance culls), {on_actor.mean():,.0f} points on actors "
          f"({mov.mean():,.0f} moving)")
    print(f"BVH builds: town {static.build_seconds:.2f} s once; prototypes {build_protos:.3f} s once (ours); "
          f"re-posing per time slice would cost town + posed actors {build_frozen:.2f} s, or a second scene of "
          f"the posed actors {1000 * build_posed:.1f} ms, per slice (a column-exact sweep has {sensor.azimuth_steps})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
