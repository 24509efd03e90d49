"""What the two peer engines share: the sample, the protocol's step loop and the raw snapshots.

Runs inside the peers' virtual environment (``benchmarks/requirements-peers.txt``: numpy,
pymunk, box2d; no grainview), so it needs numpy only. Everything here is in SI units (m, s,
kg, N, rad); each engine converts to its own units internally.

The protocol (the biaxial test of Azema et al., PRE 76, 011301, 2007), the same as
``solver.biaxial_test``: 2D, zero gravity; bottom and left walls fixed; the top wall moves
down at the constant ``velocity`` (m/s); the right wall slides along x only, pushed inward by
the force sigma0 h t (N), h the current sample height (m), t the slab thickness (1 m); grain
friction from the sample, walls frictionless, no restitution; time step from the sample.
The test runs for ``n_steps = ceil(h0 (exp(strain) - 1) / (velocity dt))`` steps, so that
eps_1 = ln(1 + (h0 - h)/h0) reaches ``strain``, with a snapshot at step 0 (the initial
state) and every ``every`` steps, and at the last step.

Raw snapshots (``snap_000000.npz``, ... in the output folder; ``export.py`` turns them into a
file of the grainview data contract) hold, in SI units:

* ``time`` (s), ``step``; ``position`` (N, 2), ``angle`` (N,), ``velocity`` (N, 2),
  ``angular_velocity`` (N,); ``wall_position`` (4, 2), ``wall_velocity`` (4, 2) for the walls
  bottom, right, top, left (a point of each wall line, as in the sample);
* one row per touching body pair (engine order, no convention applied yet): ``a``, ``b``
  (body ids: particles 0..N-1, walls N + w), ``normal`` (M, 2) the unit normal from a to b,
  ``force`` (M, 2) the resultant force exerted by a on b (N, the sum over the pair's points
  of the impulses of the last step / dt), ``n_points`` (M,) the number of points of the
  engine's contact manifold, ``points`` (M, 2, 2) their positions (m, NaN when absent) and
  ``point_fn`` (M, 2) the normal force at each point (N, 0 when absent).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time

import numpy as np

WALLS = ("bottom", "right", "top", "left")
BOTTOM, RIGHT, TOP, LEFT = range(4)
SAMPLE_KEYS = ("position", "angle", "velocity", "angular_velocity", "radius", "n_vertices", "mass", "inertia",
               "wall_position", "wall_velocity", "right_wall_mass", "sigma0", "friction", "wall_friction",
               "time_step", "thickness", "first_vertex", "local_vertices", "inradius")


def local_vertices(sample, p):
    """(n, 2) m, the vertices of particle ``p`` in its own frame, counter-clockwise, as the
    project's shape table (``solver.shapes.Shapes``) exported them (``export.sample_to_npz``)."""
    first = sample["first_vertex"]
    return sample["local_vertices"][first[p]:first[p + 1]]


def load_sample(path):
    """The sample written by ``export.sample_to_npz``: a dict of arrays and floats (SI)."""
    with np.load(path) as data:
        missing = [k for k in SAMPLE_KEYS if k not in data]
        if missing:
            raise SystemExit(f"{path}: not a cross-check sample, it lacks {missing}")
        return {k: (data[k].item() if data[k].ndim == 0 else data[k].copy()) for k in SAMPLE_KEYS}


def n_steps_for(sample, strain, velocity):
    """Steps of the test: ceil(h0 (exp(strain) - 1) / (velocity dt)), as solver.biaxial_test."""
    h0 = float(sample["wall_position"][TOP, 1] - sample["wall_position"][BOTTOM, 1])
    return int(math.ceil(h0 * (math.exp(strain) - 1.0) / velocity / sample["time_step"]))


def parse_args(engine, description, iteration_options):
    """Command line of a peer engine: SAMPLE OUT_DIR --strain --every --velocity + its
    iteration options (``iteration_options``: list of (flag, default, help))."""
    parser = argparse.ArgumentParser(prog=f"engines_{engine}.py", description=description)
    parser.add_argument("sample", help="sample .npz written by export.sample_to_npz")
    parser.add_argument("out", help="folder for the raw snapshots (created; must be empty or absent)")
    parser.add_argument("--strain", type=float, default=0.25, help="target eps_1 (default 0.25)")
    parser.add_argument("--every", type=int, default=100, help="steps between snapshots (default 100)")
    parser.add_argument("--velocity", type=float, default=0.01, help="top wall speed, m/s (default 0.01)")
    for flag, default, text in iteration_options:
        parser.add_argument(flag, type=int, default=default, help=f"{text} (default {default})")
    args = parser.parse_args()
    if not 0 < args.strain < 1:
        parser.error(f"--strain {args.strain}: expected a vertical strain in (0, 1)")
    if args.every < 1:
        parser.error(f"--every {args.every}: expected a positive number of steps")
    if not args.velocity > 0:
        parser.error(f"--velocity {args.velocity}: expected a positive speed in m/s")
    for flag, _, _ in iteration_options:
        if getattr(args, flag.lstrip("-").replace("-", "_")) < 1:
            parser.error(f"{flag}: expected a positive number of iterations")
    if os.path.isdir(args.out) and os.listdir(args.out):
        parser.error(f"{args.out} is not empty")
    return args


def run(engine, args, settings):
    """The protocol's loop. ``engine`` has ``sample`` (the dict of :func:`load_sample`),
    ``height()`` (the current sample height, m), ``step(force)`` (one step with the right wall
    pushed inward by ``force``, N) and ``snapshot()`` (the raw snapshot's arrays). It is
    stepped ``n_steps`` times, the right wall pushed by sigma0 h t computed before each step;
    a raw snapshot is written at step 0, every ``args.every`` steps and at the last step; then
    ``meta.json`` (``settings``, steps, snapshots, wall times in s). Returns the wall time of
    the stepping alone (s)."""
    sample = engine.sample
    n_steps = n_steps_for(sample, args.strain, args.velocity)
    os.makedirs(args.out, exist_ok=True)
    thickness, sigma0 = sample["thickness"], sample["sigma0"]
    written, stepping = 0, 0.0
    start = time.perf_counter()
    for k in range(n_steps + 1):
        if k:
            t0 = time.perf_counter()
            engine.step(sigma0 * engine.height() * thickness)
            stepping += time.perf_counter() - t0
        if k % args.every == 0 or k == n_steps:
            snap = engine.snapshot()
            snap.update(step=k, time=k * sample["time_step"])
            np.savez(os.path.join(args.out, f"snap_{written:06d}.npz"), **snap)
            written += 1
        if k and k % 5000 == 0:
            print(f"{args.out}: step {k}/{n_steps}, {time.perf_counter() - start:.0f} s", file=sys.stderr, flush=True)
    meta = dict(settings, n_steps=n_steps, snapshots=written, strain=args.strain, every=args.every,
                velocity=args.velocity, stepping_s=stepping, wall_s=time.perf_counter() - start)
    with open(os.path.join(args.out, "meta.json"), "w") as fh:
        json.dump(meta, fh, indent=1)
    return stepping


def pairs_to_arrays(rows):
    """Stack the per-pair rows ``(a, b, normal, force, points, point_fn)`` (SI) into the raw
    snapshot's contact arrays."""
    m = len(rows)
    out = dict(a=np.empty(m, np.int32), b=np.empty(m, np.int32), normal=np.empty((m, 2)), force=np.empty((m, 2)),
               n_points=np.zeros(m, np.int8), points=np.full((m, 2, 2), np.nan), point_fn=np.zeros((m, 2)))
    for r, (a, b, normal, force, points, point_fn) in enumerate(rows):
        out["a"][r], out["b"][r] = a, b
        out["normal"][r], out["force"][r] = normal, force
        k = len(points)
        out["n_points"][r] = k
        out["points"][r, :k] = points
        out["point_fn"][r, :k] = point_fn
    return out
