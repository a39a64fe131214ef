#!/usr/bin/env python3
"""Compare our primitive map + ray trace with Embree on one thread, on the same shadow rays.

The CPU peer of `host_demo render`: Embree (through the `embreex` package, used here only, never in the
product) builds its BVH over exactly the triangles the GPU traces and answers an occlusion query for
exactly the GPU's shadow rays. The script prints one table row:

  model  rays  triangles  Embree build ms  Embree trace ms  ours ms  ours/Embree  mismatches

- Embree build ms: median wall clock of rtcCommitScene (the BVH build; embreex commits on the first
  query, so the first query is a one-ray call). Creating the geometry and copying the vertices into it
  is reported on a separate line, not included.
- Embree trace ms: median wall clock of one rtcOccluded1 per ray over every ray (embreex's own C loop).
- ours ms: the sum of frame.json's `gpu_ms` entries whose name starts with "primitive map", plus
  "ray trace" (the names summed are printed), or --ours-ms.
- ours/Embree: ours ms / (Embree build ms + Embree trace ms); at most 1 means ours is no slower.
- mismatches: rays whose Embree visibility (occluded: 0, else 1) differs from the pixel's value in
  rt_visibility.exr (read with the OpenEXR package), and how many of those the exact reference calls
  near an edge (ray_near_edge.u8), where two correct tracers may disagree.

One thread: embreex creates its device with rtcNewDevice(NULL) and offers no configuration string, so
"threads=1" cannot be passed. Instead the script pins itself to one CPU (sched_setaffinity) before it
loads Embree: TBB, and with it Embree, then sizes its thread pool to that one CPU. The number of OS
threads of the process after the build is printed as a check (1 expected).

Inputs, in the folder given (all written by `hrts_lab ray-dump`, see
lab/src/ray_dump.rs):
  triangles.f32     f32 LE, 9 per triangle (frame coordinates: world minus the frame origin)
  rays.f32          f32 LE, 8 per ray: ox oy oz dx dy dz t_max pixel (pixel = y * width + x)
  ray_near_edge.u8  optional, 1 byte per ray: 1 where the exact reference is ambiguous
  rays.json         sizes and light kind
  frame.json        per-pass GPU milliseconds (medians over frames), device
  rt_visibility.exr the GPU's ray-traced visibility (1 = lit)

Requirements: numpy, embreex, OpenEXR (pip). Where pip refuses to install into the system Python,
use a virtual environment, e.g. in the git-ignored .dev/ folder:
  python3 -m venv .dev/embree-venv && .dev/embree-venv/bin/pip install embreex numpy OpenEXR

How to run
----------
  # 1. Render a frame's hard shadow and dump its rays:
  cargo run --release -p hrts_lab -- ray-dump --obj ../shared/models/02_stanford_bunny_69k.obj \\
      --out out/bunny
  # 2. Time Embree on the same rays and compare:
  .dev/embree-venv/bin/python scripts/embree_compare.py out/bunny
  # options: --model NAME (default: the folder's name), --runs N (default 5), --cpu K (the CPU to
  # pin to), --no-robust (Embree's fast, non-robust traversal), --ours-ms MS (our time measured
  # another way, e.g. wall clock, instead of frame.json)
"""

import argparse
import json
import os
import statistics
import sys
import time
from pathlib import Path

INSTALL_HINT = (
    "install it with pip, e.g. in a virtual environment in the git-ignored .dev/ folder:\n"
    "  python3 -m venv .dev/embree-venv && .dev/embree-venv/bin/pip install embreex numpy OpenEXR\n"
    "then run this script with .dev/embree-venv/bin/python"
)

RAY_FLOATS = 8
TRIANGLE_FLOATS = 9


def fail(message):
    print(f"embree_compare: {message}", file=sys.stderr)
    sys.exit(2)


def parse_args():
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("dir", type=Path, help="output folder of `hrts_lab ray-dump`")
    parser.add_argument("--model", help="model name in the table (default: the folder's name)")
    parser.add_argument("--runs", type=int, default=5, help="timed runs; medians are reported (default 5)")
    parser.add_argument(
        "--cpu", type=int, help="CPU to pin the process to (default: the lowest the process may use)"
    )
    parser.add_argument(
        "--no-robust",
        action="store_true",
        help="build the Embree scene without RTC_SCENE_FLAG_ROBUST (default: robust, like our watertight test)",
    )
    parser.add_argument(
        "--ours-ms", type=float, help="our time in ms, measured another way, instead of frame.json's timings"
    )
    args = parser.parse_args()
    if args.runs < 1:
        parser.error("--runs must be at least 1")
    return args


def pin_to_one_cpu(cpu):
    """Restricts the process to one CPU before numpy and Embree start any thread pool."""
    allowed = os.sched_getaffinity(0)
    cpu = min(allowed) if cpu is None else cpu
    if cpu not in allowed:
        fail(f"--cpu {cpu} is not among the CPUs this process may use: {sorted(allowed)}")
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ[var] = "1"
    os.sched_setaffinity(0, {cpu})
    return cpu


def os_threads():
    return len(os.listdir("/proc/self/task"))


def load_inputs(folder, np):
    for name in ("triangles.f32", "rays.f32", "rays.json", "frame.json", "rt_visibility.exr"):
        if not (folder / name).is_file():
            hint = " (write it with hrts_lab ray-dump)" if name.endswith((".f32", "rays.json")) else ""
            if name == "rt_visibility.exr":
                hint = " (render with --mode hard or hybrid)"
            fail(f"{folder / name} is missing{hint}")
    meta = json.loads((folder / "rays.json").read_text())
    frame = json.loads((folder / "frame.json").read_text())
    tris = np.fromfile(folder / "triangles.f32", dtype="<f4")
    rays = np.fromfile(folder / "rays.f32", dtype="<f4")
    if tris.size % TRIANGLE_FLOATS or rays.size % RAY_FLOATS:
        fail("triangles.f32 or rays.f32 has a size that is not a whole number of records")
    tris = tris.reshape(-1, 3, 3)
    rays = rays.reshape(-1, RAY_FLOATS)
    if len(tris) != meta["triangles"] or len(rays) != meta["rays"]:
        fail(
            f"rays.json says {meta['rays']} rays and {meta['triangles']} triangles, the files hold "
            f"{len(rays)} and {len(tris)}"
        )
    if (meta["width"], meta["height"]) != (frame["width"], frame["height"]):
        fail("rays.json and frame.json disagree on the frame size: not from the same render")
    near_edge = None
    if (folder / "ray_near_edge.u8").is_file():
        near_edge = np.fromfile(folder / "ray_near_edge.u8", dtype=np.uint8)
        if len(near_edge) != len(rays):
            fail("ray_near_edge.u8 does not hold one byte per ray")
    return meta, frame, tris, rays, near_edge


def read_visibility(path, width, height, np):
    try:
        import OpenEXR
    except ImportError:
        fail("the OpenEXR package is needed to read rt_visibility.exr: " + INSTALL_HINT)
    channels = OpenEXR.File(str(path)).channels()
    if "R" in channels:
        values = channels["R"].pixels
    elif "RGBA" in channels:
        values = channels["RGBA"].pixels[..., 0]
    else:
        fail(f"{path} has no R channel (channels: {sorted(channels)})")
    if values.shape != (height, width):
        fail(f"{path} is {values.shape[1]}x{values.shape[0]}, the rays are for {width}x{height}")
    return np.asarray(values, dtype=np.float32).reshape(-1)


WALL = "screen-space submission (wall clock)"


def our_time(frame, override):
    timings = frame.get("gpu_ms", {})
    if override is not None:
        return override, "--ours-ms"
    if frame.get("device", {}).get("device_type", "").upper() == "CPU" or "llvmpipe" in frame.get("device", {}).get("name", ""):
        # A CPU device's timestamps do not bracket its compute work: take the host's wall clock of the
        # submission that holds the primitive map and the ray trace (render with --mode hard
        # --no-antialiasing so it holds nothing else but the output copy).
        if WALL not in timings:
            fail(f"frame.json has no '{WALL}' timing")
        return timings[WALL], f"'{WALL}' {timings[WALL]:.3f} (CPU device: wall clock, not timestamps)"
    names = sorted(n for n in timings if n.startswith("primitive map"))
    if "ray trace" not in timings:
        fail("frame.json has no 'ray trace' timing: render with --mode hard or hybrid")
    if not names:
        fail("frame.json has no timing whose name starts with 'primitive map'")
    names.append("ray trace")
    return sum(timings[n] for n in names), " + ".join(f"'{n}' {timings[n]:.3f}" for n in names)


def time_embree(tris, rays, runs, robust, np):
    from embreex import mesh_construction, rtcore_scene

    origins = np.ascontiguousarray(rays[:, 0:3])
    directions = np.ascontiguousarray(rays[:, 3:6])
    t_max = np.ascontiguousarray(rays[:, 6])
    probe = (np.zeros((1, 3), np.float32), np.array([[0, 0, 1]], np.float32), np.zeros(1, np.float32))
    setup, build, trace = [], [], []
    result = None
    threads = 0
    for _ in range(runs):
        t0 = time.perf_counter()
        scene = rtcore_scene.EmbreeScene(robust=robust)
        mesh_construction.TriangleMesh(scene, tris)
        t1 = time.perf_counter()
        scene.run(*probe, query="OCCLUDED")  # rtcCommitScene, then one ray of length 0
        t2 = time.perf_counter()
        threads = max(threads, os_threads())
        hits = scene.run(origins, directions, dists=t_max.copy(), query="OCCLUDED")
        t3 = time.perf_counter()
        setup.append(t1 - t0)
        build.append(t2 - t1)
        trace.append(t3 - t2)
        result = hits
        del scene
    visibility = np.where(result != -1, 0.0, 1.0).astype(np.float32)
    ms = lambda v: 1e3 * statistics.median(v)
    return ms(setup), ms(build), ms(trace), visibility, threads


def main():
    args = parse_args()
    cpu = pin_to_one_cpu(args.cpu)
    try:
        import embreex  # noqa: F401
        from embreex import mesh_construction, rtcore_scene  # noqa: F401
    except ImportError as e:
        fail(f"embreex (Embree for Python) is not installed or does not load ({e}): " + INSTALL_HINT)
    import numpy as np

    meta, frame, tris, rays, near_edge = load_inputs(args.dir, np)
    width, height = meta["width"], meta["height"]
    gpu = read_visibility(args.dir / "rt_visibility.exr", width, height, np)
    ours, ours_how = our_time(frame, args.ours_ms)

    setup_ms, build_ms, trace_ms, embree_vis, threads = time_embree(
        tris, rays, args.runs, not args.no_robust, np
    )
    pixels = rays[:, 7].astype(np.int64)
    differ = embree_vis != gpu[pixels]
    mismatches = int(differ.sum())
    near = int((differ & (near_edge != 0)).sum()) if near_edge is not None else None

    device = frame.get("device", {}).get("name", "?")
    model = args.model or args.dir.resolve().name
    ratio = ours / (build_ms + trace_ms) if build_ms + trace_ms > 0 else float("inf")
    mismatch_text = f"{mismatches}" + (f" ({near} near edge)" if near is not None else "")

    print(f"frame: {width}x{height} px, {meta['light']} light; ours on {device}")
    print(f"ours: {ours_how} = {ours:.3f} ms")
    print(
        f"Embree {embreex_version()}: one thread (process pinned to CPU {cpu}; {threads} OS thread(s) "
        f"after the build), {'robust' if not args.no_robust else 'non-robust'} scene, medians of "
        f"{args.runs} runs; geometry setup (not in build) {setup_ms:.3f} ms"
    )
    header = ["model", "rays", "triangles", "Embree build ms", "Embree trace ms", "ours ms", "ours/Embree", "mismatches"]
    row = [
        model,
        f"{len(rays)}",
        f"{len(tris)}",
        f"{build_ms:.3f}",
        f"{trace_ms:.3f}",
        f"{ours:.3f}",
        f"{ratio:.3f}",
        mismatch_text,
    ]
    widths = [max(len(h), len(c)) for h, c in zip(header, row)]
    print("| " + " | ".join(h.ljust(w) for h, w in zip(header, widths)) + " |")
    print("|" + "|".join("-" * (w + 2) for w in widths) + "|")
    print("| " + " | ".join(c.ljust(w) for c, w in zip(row, widths)) + " |")


def embreex_version():
    try:
        from importlib.metadata import version

        return f"(embreex {version('embreex')})"
    except Exception:
        return "(embreex)"


if __name__ == "__main__":
    main()
