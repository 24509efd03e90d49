"""Box2D and pymunk runs of the cross-check as datasets of the contract.

The cross-check harness (``benchmarks/crosscheck/``) drives Box2D 2.3 and pymunk through the
paper's biaxial test on a sample of this project and saves each engine's state as *raw
snapshots*: a folder of ``snap_000000.npz``, ``snap_000001.npz``, ... and a ``meta.json`` (the
engine, its version and settings, the protocol), beside the sample's own ``.npz`` (masses,
radii, vertex counts, time step and, for polygons other than regular ones, ``vertices``: each
polygon's vertices in its own frame, as the contract stores them, :mod:`grainview.contract.shapes`;
passed on to the file as they are). Each raw snapshot holds, in SI units:

* ``time`` (s), ``step``; ``position`` (N, 2), ``angle`` (N,), ``velocity`` (N, 2),
  ``angular_velocity`` (N,); ``wall_position``, ``wall_velocity`` (4, 2) for the walls bottom,
  right, top, left;
* one row per touching body pair, in the engine's order: ``a``, ``b`` (particles 0..N-1,
  walls N + w), ``normal`` (M, 2) the unit normal from a to b, ``force`` (M, 2) the resultant
  force exerted by a on b (the pair's impulses of the last step over the time step),
  ``n_points`` (M,) the points of the engine's contact manifold, ``points`` (M, 2, 2) their
  positions (NaN when absent) and ``point_fn`` (M, 2) their normal forces.

The contract's conventions applied, once for both engines:

* one entry per body pair, ``i < j`` (for a wall contact ``i`` is the particle and
  ``j = N + w``); ``normal`` from i to j (the engine's normal, reversed when the engine's first
  body is j); ``fn``, ``ft`` the components along ``normal`` and ``t = (-n_y, n_x)`` of the
  force exerted by i on j; only pairs with ``fn > 0`` are kept;
* ``kind`` 2 (double) when the engine's manifold holds two points (Box2D ``pointCount == 2``,
  pymunk ``len(contact_point_set.points) == 2``), else 1: a geometric criterion, as this
  project's solver's edge-to-edge test, not whether both points carry force;
* ``point``: the application point of the resultant, the manifold's points weighted by their
  normal forces (by equal weights when none carries any);
* ``branch``: ``x_j - x_i`` for particle pairs, ``point - x_i`` for wall contacts.

Besides the required variables the file holds ``velocity``, ``angular_velocity``,
``wall_position``, ``wall_velocity``, ``wall_force`` (the sum of the contact forces exerted by
the particles on each wall), ``normal_impulse`` (N s: each manifold point's normal force times
the time step, 0 for a simple contact's second point) and ``step``.
"""

from __future__ import annotations

import glob
import json
import math
import os
import re
import zipfile
import zlib

import numpy as np

from ..contract.errors import FileFormatError, ParameterError
from ..contract.schema import contact_slots
from .checks import TIME_LIMIT_S, UNIT_TOLERANCE, Limits, check_contacts, check_snapshot, check_step, input_file, \
    input_folder

__all__ = ["WALLS", "WALL_NORMALS", "peer_contacts", "wall_forces", "peer_snapshots", "open_peer", "open_box2d",
           "open_pymunk", "convert_peer"]

WALLS = ("bottom", "right", "top", "left")
WALL_NORMALS = np.array([[0.0, 1.0], [-1.0, 0.0], [0.0, -1.0], [1.0, 0.0]])
"""Inward unit normals of the cross-check's walls."""
SNAPSHOT_KEYS = ("time", "step", "position", "angle", "velocity", "angular_velocity", "wall_position",
                 "wall_velocity", "a", "b", "normal", "force", "n_points", "points", "point_fn")
SAMPLE_KEYS = ("radius", "n_vertices", "mass", "inertia", "time_step")
OPTIONAL = ("velocity", "angular_velocity", "wall_position", "wall_velocity", "wall_force", "normal_impulse", "step")
SNAPSHOT_FIELDS = ("time", "position", "angle", "contacts", "box_min", "box_max", "raw") + OPTIONAL
"""What :func:`peer_snapshots` yields for each snapshot: the writer's arguments and the raw arrays."""


def peer_contacts(raw, position, dt) -> dict:
    """The contract's contact arrays of one raw snapshot's pair arrays (module docstring),
    sorted by (i, j), with ``normal_impulse`` (M, 2) = the points' normal forces times the time
    step ``dt`` (s)."""
    a, b = raw["a"].astype(np.int64), raw["b"].astype(np.int64)
    n = len(position)
    swap = a > b
    i, j = np.where(swap, b, a), np.where(swap, a, b)
    sign = np.where(swap, -1.0, 1.0)[:, None]
    normal = raw["normal"] * sign
    force = raw["force"] * sign  # exerted by i on j
    normal = normal / np.linalg.norm(normal, axis=1, keepdims=True)
    tangent = np.stack([-normal[:, 1], normal[:, 0]], -1)
    fn = np.sum(force * normal, axis=1)
    ft = np.sum(force * tangent, axis=1)
    present = np.arange(2)[None, :] < raw["n_points"][:, None]
    weights = np.where(present, np.maximum(raw["point_fn"], 0.0), 0.0)
    weights = np.where((weights.sum(1) > 0)[:, None], weights, present.astype(float))
    points = np.where(present[..., None], raw["points"], 0.0)
    point = np.sum(points * weights[..., None], axis=1) / np.sum(weights, axis=1)[:, None]
    centre_i = position[i]
    branch = np.where((j >= n)[:, None], point - centre_i, position[np.minimum(j, n - 1)] - centre_i)
    kind = np.where(raw["n_points"] == 2, 2, 1).astype(np.int8)
    keep = fn > 0
    order = np.lexsort((j[keep], i[keep]))
    contacts = dict(i=i, j=j, kind=kind, normal=normal, fn=fn, ft=ft, point=point, branch=branch,
                    normal_impulse=np.where(present, raw["point_fn"], 0.0) * dt)
    return {name: value[keep][order] for name, value in contacts.items()}


def wall_forces(contacts, n) -> np.ndarray:
    """(4, 2) total force (N) exerted by the particles on each wall, from contract contacts
    of ``n`` particles."""
    out = np.zeros((4, 2))
    wall = contacts["j"] >= n
    normal = contacts["normal"][wall]
    force = (contacts["fn"][wall, None] * normal
             + contacts["ft"][wall, None] * np.stack([-normal[:, 1], normal[:, 0]], -1))
    np.add.at(out, contacts["j"][wall] - n, force)
    return out


def _load(path, keys, what):
    """The arrays of an ``.npz`` file; one line naming it when it lacks one of ``keys`` or
    cannot be read (empty, truncated, damaged: an engine killed while writing it)."""
    path = input_file(path, what)
    try:
        with open(path, "rb") as fh, np.load(fh, allow_pickle=False) as data:
            missing = [k for k in keys if k not in data.files]
            if missing:
                raise FileFormatError(f"{path}: not {what}: it lacks {', '.join(missing)}")
            return {k: data[k] for k in data.files}
    except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile, zlib.error) as exc:
        if os.path.getsize(path) == 0:
            raise FileFormatError(f"{path}: an empty file, not {what} (an engine stopped while writing it?)") from None
        raise FileFormatError(f"{path}: cannot be read as {what}: a truncated or damaged .npz ({exc})") from None


def _snapshot_files(raw_dir):
    """The raw snapshots ``snap_000000.npz``, ``snap_000001.npz``, ... of a folder, in order; one
    line when there are none or one is missing between two others."""
    found = {}
    for path in glob.glob(os.path.join(raw_dir, "snap_*.npz")):
        match = re.fullmatch(r"snap_(\d+)\.npz", os.path.basename(path))
        if match:
            found[int(match.group(1))] = path
    if not found:
        raise FileFormatError(f"{raw_dir}: no raw snapshots (snap_*.npz): did the engine run?")
    missing = sorted(set(range(max(found) + 1)) - set(found))
    if missing:
        raise FileFormatError(f"{raw_dir}: no snap_{missing[0]:06d}.npz, but snapshots up to "
                              f"snap_{max(found):06d}.npz; expected the raw snapshots numbered from 0 without a gap")
    return [found[k] for k in sorted(found)]


_SHAPES = {"time": (), "step": (), "position": ("N", 2), "angle": ("N",), "velocity": ("N", 2),
           "angular_velocity": ("N",), "wall_position": (4, 2), "wall_velocity": (4, 2), "a": ("M",), "b": ("M",),
           "normal": ("M", 2), "force": ("M", 2), "n_points": ("M",), "points": ("M", 2, 2), "point_fn": ("M", 2)}
"""The shape of each array of a raw snapshot: N particles, M contacts."""


def _check_shapes(raw, n, path):
    """One line for an array of a raw snapshot whose shape is not its format's."""
    sizes = {"N": n, "M": np.shape(raw["a"])[0] if np.ndim(raw["a"]) == 1 else -1}
    for name, shape in _SHAPES.items():
        expected = tuple(sizes.get(d, d) for d in shape)
        found = np.shape(raw[name])
        if found != expected and not (shape == () and found == (1,)):
            words = "x".join(str(d) for d in shape) or "a scalar"
            raise FileFormatError(f"{path}: {name} of shape {found}; expected {words} ({n} particles, "
                                  f"{sizes['M']} contacts)")


def peer_snapshots(raw_dir, sample, engine=None):
    """Read a peer engine's raw snapshots one at a time, as the contract's per-snapshot arrays.

    Parameters
    ----------
    raw_dir : str or path-like
        The engine's output folder (``snap_*.npz`` and ``meta.json``).
    sample : str or path-like
        The sample's ``.npz`` the engine started from (``radius``, ``n_vertices``, ``mass``,
        ``inertia``, ``time_step``; optionally ``vertices``, (N, V, 2) m).
    engine : {"box2d", "pymunk"}, optional
        Refuse a folder written by another engine (``meta.json``'s ``engine``).

    Returns
    -------
    (static, iterator)
        ``static``: the particles' arrays (``vertices`` None when the sample has none),
        ``meta`` (the engine's settings) and ``attrs`` (global attributes of the run); the
        iterator yields one dict per snapshot for
        :meth:`grainview.contract.writer.SnapshotWriter.append`, with ``raw`` (the raw arrays) besides.

    Raises
    ------
    FileFormatError, ParameterError
        One line: no snapshots, no or bad ``meta.json``, another engine's folder, a sample or
        snapshot lacking arrays, a snapshot whose particle count differs from the sample's.
    """
    raw_dir = input_folder(raw_dir, "a peer engine's folder of raw snapshots (snap_*.npz and meta.json)")
    files = _snapshot_files(raw_dir)
    try:
        with open(os.path.join(raw_dir, "meta.json")) as fh:
            meta = json.load(fh)
    except (OSError, ValueError) as exc:
        raise FileFormatError(f"{raw_dir}: no readable meta.json ({exc})") from None
    if not isinstance(meta, dict):
        raise FileFormatError(f"{os.path.join(raw_dir, 'meta.json')}: a JSON {type(meta).__name__}; expected an "
                              "object of the engine's settings ({\"engine\": ..., \"snapshots\": ...})")
    announced = meta.get("snapshots")
    if isinstance(announced, int) and not isinstance(announced, bool) and announced != len(files):
        raise FileFormatError(f"{raw_dir}: {len(files)} raw snapshots (snap_*.npz), but meta.json announces "
                              f"{announced}")
    if engine is not None and meta.get("engine") != engine:
        raise ParameterError(f"{raw_dir}: written by {meta.get('engine')!r}, not {engine!r}")
    data = _load(sample, SAMPLE_KEYS, "a cross-check sample")
    radius = np.asarray(data["radius"], float)
    n = radius.size
    dt = float(data["time_step"])
    sample = os.fspath(sample)
    limits = Limits(radius, 1.0, sample, mass=data["mass"], inertia=data["inertia"], n_vertices=data["n_vertices"])
    if not (math.isfinite(dt) and 0 < dt <= TIME_LIMIT_S):
        raise FileFormatError(f"{sample}: time_step = {dt:.6g}; expected a finite time step > 0 in s")
    attrs = {f"engine_{k}": v for k, v in meta.items() if isinstance(v, (str, int, float))}
    attrs.update({"source": str(meta.get("engine", "peer engine")), "time_step_s": dt})
    for key in ("strain", "velocity", "every", "n_steps"):
        if key in meta:
            attrs[{"strain": "strain_target", "velocity": "wall_velocity_m_s", "every": "snapshot_every",
                   "n_steps": "biaxial_steps"}[key]] = meta[key]
    static = dict(radius=radius, n_vertices=np.asarray(data["n_vertices"], np.int32),
                  mass=np.asarray(data["mass"], float), inertia=np.asarray(data["inertia"], float), meta=meta,
                  vertices=np.asarray(data["vertices"], float) if "vertices" in data else None,
                  attrs=attrs, files=files)

    def snapshots():
        for path in files:
            raw = _load(path, SNAPSHOT_KEYS, "a raw snapshot of the cross-check")
            if np.ndim(raw["position"]) != 2 or len(raw["position"]) != n:
                raise FileFormatError(f"{path}: {len(raw['position'])} particles, the sample has {n}")
            _check_shapes(raw, n, path)
            _check_raw(limits, raw, path)
            check_step(int(raw["step"]), path)
            contacts = peer_contacts(raw, raw["position"], dt)
            check_contacts(limits, raw["position"], contacts, path,
                           lambda k: f"particle {k}" if k < n else f"the {WALLS[k - n]} wall")
            normal_impulse = contacts.pop("normal_impulse")
            walls = raw["wall_position"]
            yield dict(time=float(raw["time"]), position=raw["position"], angle=raw["angle"], contacts=contacts,
                       box_min=np.array([walls[3, 0], walls[0, 1]]), box_max=np.array([walls[1, 0], walls[2, 1]]),
                       velocity=raw["velocity"], angular_velocity=raw["angular_velocity"], wall_position=walls,
                       wall_velocity=raw["wall_velocity"], wall_force=wall_forces(contacts, n),
                       normal_impulse=normal_impulse, step=int(raw["step"]), raw=raw)

    return static, snapshots()


def _check_raw(limits, raw, path):
    """One line for a raw snapshot's value that is not finite or is absurd (a manifold's absent
    point is NaN: only the present ones are checked)."""
    middle = np.median(np.asarray(raw["position"], float).reshape(-1, 2), axis=0)
    contact = lambda k: f"contact {k}"  # noqa: E731  (a row of the pair arrays)
    for name, kind in (("time", "time"), ("position", "position"), ("angle", "angle"), ("velocity", "speed"),
                       ("angular_velocity", "angular_velocity"), ("wall_position", "position"),
                       ("wall_velocity", "speed"), ("normal", "unit"), ("force", "force")):
        values = np.asarray(raw[name], float)
        if values.size == 0:
            continue
        values = values.reshape(values.shape[0] if values.ndim else 1, -1)
        what = "contact" if name in ("normal", "force") else "wall" if name.startswith("wall") else "particle"
        rows = (lambda k: "the snapshot") if name == "time" else (lambda k, what=what: f"{what} {k}")
        limits.check(values, name, kind, path, rows=rows, centre=middle if kind == "position" else None)
    a, b, count = (np.asarray(raw[key], float) for key in ("a", "b", "n_points"))
    limits.check(np.column_stack([a, b, count]), ("a", "b", "n_points"), "number", path, rows=contact)
    n = limits.radius.size
    step = float(np.asarray(raw["step"], float).reshape(-1)[0])
    if not (np.isfinite(step) and step == round(step) and step >= 0):
        raise FileFormatError(f"{path}: step = {step:g}; expected a whole number >= 0")
    for name, values in (("a", a), ("b", b)):
        bad = (values != np.round(values)) | (values < 0) | (values >= n + len(WALLS))
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            raise FileFormatError(f"{path}: contact {k}: {name} = {values[k]:g}; expected a body index, a particle "
                                  f"0 .. {n - 1} or a wall {n} .. {n + len(WALLS) - 1}")
    bad = (a == b) | ((a >= n) & (b >= n))
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise FileFormatError(f"{path}: contact {k} of bodies {a[k]:g} and {b[k]:g}; expected a particle and another "
                              "body")
    bad = (count != 1) & (count != 2)
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise FileFormatError(f"{path}: contact {k}: n_points = {count[k]:g}; expected 1 or 2 (the points of the "
                              "engine's contact manifold)")
    length = np.hypot(*np.asarray(raw["normal"], float).reshape(-1, 2).T)
    bad = np.abs(length - 1) > UNIT_TOLERANCE
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise FileFormatError(f"{path}: contact {k}: normal of length {length[k]:.6g}; expected a unit vector")
    present = np.arange(2)[None, :] < count[:, None]
    limits.check(np.where(present, raw["point_fn"], 0.0), "point_fn", "force", path, rows=contact)
    points = np.where(present[..., None], raw["points"], middle)
    limits.check(points.reshape(-1, 2), "points", "position", path, rows=lambda k: f"contact {k // 2}",
                 centre=middle)


def open_peer(raw_dir, sample, engine=None):
    """A peer engine's run (:func:`peer_snapshots`) as an in-memory dataset of the contract."""
    from ..contract.dataset import make_dataset

    static, stream = peer_snapshots(raw_dir, sample, engine)
    snaps = list(stream)
    limits = Limits(static["radius"], 1.0, os.fspath(sample), mass=static["mass"], inertia=static["inertia"])
    for path, snap in zip(static["files"], snaps):
        check_snapshot(limits, snap, path)
    n = static["radius"].size
    slots = max([contact_slots(n, 4)] + [len(s["contacts"]["i"]) for s in snaps])
    impulse = np.zeros((len(snaps), slots, 2))
    for k, s in enumerate(snaps):
        impulse[k, :len(s["normal_impulse"])] = s["normal_impulse"]
    optional = {name: np.stack([s[name] for s in snaps]) for name in OPTIONAL if name != "normal_impulse"}
    optional["normal_impulse"] = impulse
    if static["vertices"] is not None:
        optional["vertices"] = static["vertices"]
    return make_dataset(radius=static["radius"], n_vertices=static["n_vertices"], mass=static["mass"],
                        inertia=static["inertia"], position=np.stack([s["position"] for s in snaps]),
                        angle=np.stack([s["angle"] for s in snaps]),
                        contacts=[s["contacts"] for s in snaps], box_min=np.stack([s["box_min"] for s in snaps]),
                        box_max=np.stack([s["box_max"] for s in snaps]), time=np.array([s["time"] for s in snaps]),
                        n_walls=4, wall_names=WALLS, attrs=static["attrs"], n_contact_slots=slots,
                        wall_normal=WALL_NORMALS, **optional)


def open_box2d(raw_dir, sample):
    """A Box2D run of the cross-check (:func:`open_peer` refusing another engine's folder)."""
    return open_peer(raw_dir, sample, "box2d")


def open_pymunk(raw_dir, sample):
    """A pymunk run of the cross-check (:func:`open_peer` refusing another engine's folder)."""
    return open_peer(raw_dir, sample, "pymunk")


def convert_peer(out, raw_dir, sample, *, engine=None, attrs=None, extra=None, overwrite=False, compress=True) -> int:
    """Write a peer engine's run as a file of the contract, snapshot by snapshot.

    ``attrs``: more global attributes; ``extra``: a function of a snapshot's raw arrays
    returning more optional variables for it (the harness adds ``max_interpenetration``,
    measured by this project's narrow phase). Written under a hidden temporary name, then
    compressed (unless ``compress=False``) and moved into place; an existing ``out`` is
    refused unless ``overwrite``. Returns the number of snapshots.
    """
    from .convert import chain_first, check_out, write_snapshots

    inputs = sorted(glob.glob(os.path.join(os.fspath(raw_dir), "*"))) + [os.fspath(sample)]
    out = check_out(out, overwrite, inputs)
    static, stream = peer_snapshots(raw_dir, sample, engine)
    if extra is not None:  # each snapshot's extra variables, computed once
        stream = (dict(snap, **extra(snap["raw"])) for snap in stream)
    first = next(stream)
    more = tuple(name for name in first if name not in SNAPSHOT_FIELDS)
    static = dict(static, n_walls=4, wall_names=WALLS, wall_normal=WALL_NORMALS, attrs=dict(static["attrs"],
                                                                                          **(attrs or {})))
    slots = contact_slots(static["radius"].size, 4)  # the writer's contact slots

    def prepare(snap):
        snap.pop("raw")
        points = snap.pop("normal_impulse")
        impulse = np.zeros((slots, 2))
        impulse[:len(points)] = points
        return dict(snap, normal_impulse=impulse)

    return write_snapshots(out, static, chain_first(first, stream), OPTIONAL + more, overwrite=overwrite,
                           compress=compress, label="peer", prepare=prepare, inputs=inputs)
