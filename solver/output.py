"""Writing a simulation into a netCDF file of the grainview data contract, snapshot by
snapshot (through :class:`grainview.contract.writer.SnapshotWriter`).

Contacts are written per body pair: a double contact's two points become one slot with the
resultant force and its application point (the fn-weighted mean of the two points, their
midpoint when both forces vanish). By default only force-bearing contacts (f_n > 0) are
written: pairs within the alert distance that carry nothing are not contacts of the packing.
With ``near`` (m; the recorder uses the alert distance) the open or unloaded pairs whose gap is
<= near are written too, with f_n = f_t = 0, so that an analysis can count them as a code that
keeps every pair within its alert distance does (``grainview.analysis.contacts.in_network``); the file
then says so in its attribute ``near_contacts_m``. ``gap`` is the pair's smallest separation
along the normal at the start of the step (negative: overlap). :func:`written_pairs` alone
decides what is written, for the contacts and for the restart impulses alike.

The kind is the detection's (geometric: two edges facing each other within the alert distance
give a double contact), also when only one of its two points carries a force. ``branch`` is
x_j - x_i for particle pairs (positions of the snapshot; in a periodic cell its minimum image,
and the contact point beside x_i) and the contact point minus x_i for wall contacts; ``wall_force`` is the total force exerted by the particles on each wall, sum of
f over its contacts (f = f_n n + f_t t, force of i on j = the wall).
"""

from __future__ import annotations

import shlex
import sys
import warnings

import numpy as np

from grainview.contract.schema import DIAGNOSTICS
from grainview.contract.errors import FileFormatError, OutputError, ParameterError
from grainview.contract.writer import DEFAULT_COMPLEVEL, SnapshotWriter, compress_file, last_complete_value, lock_file

from . import __version__
from .contact_points import point_forces, rank_in_pair
from .interrupt import Terminated, sigterm_raises

OPTIONAL = ("velocity", "angular_velocity", "wall_position", "wall_velocity", "wall_force",
            "normal_impulse", "tangential_impulse", "gap", *DIAGNOSTICS)


def _pair_sums(pts, values):
    """Sum of ``values`` (one per contact point) over the points of each pair."""
    return np.bincount(pts.pair, weights=values, minlength=pts.n_pairs)


def _pair_gaps(pts):
    """Smallest gap (m) of each pair's points."""
    gap = np.full(pts.n_pairs, np.inf)
    np.minimum.at(gap, pts.pair, pts.gap)
    return gap


def written_pairs(sim, near=None, n_slots=None):
    """Which body pairs of the last step are written, as a boolean mask over its pairs.

    The force-bearing pairs (resultant f_n > 0) and, with ``near`` (m), every other pair
    whose smallest gap is <= near. When ``n_slots`` is given and the pairs do not fit, the
    near pairs with the largest gaps are left out (with a warning); force-bearing pairs are
    always kept.
    """
    pts = sim.points
    if pts is None or len(pts.pair) == 0:
        return np.zeros(0, bool)
    keep = _pair_sums(pts, sim.impulse[:, 0]) > 0
    if near is None:
        return keep
    gap = _pair_gaps(pts)
    near_pairs = ~keep & (gap <= near)
    if n_slots is not None and keep.sum() + near_pairs.sum() > n_slots:
        room = max(int(n_slots - keep.sum()), 0)
        candidates = np.flatnonzero(near_pairs)
        chosen = candidates[np.argsort(gap[candidates], kind="stable")[:room]]
        warnings.warn(f"step {sim.step_index}: {near_pairs.sum()} near pairs do not all fit in the file's "
                      f"{n_slots} contact slots; the {near_pairs.sum() - room} farthest are not written",
                      RuntimeWarning, stacklevel=2)
        near_pairs = np.zeros_like(near_pairs)
        near_pairs[chosen] = True
    return keep | near_pairs


def pair_contacts(sim, near=None, n_slots=None):
    """The contacts of the last step, one entry per written body pair (dict of contract
    arrays, ``gap`` included); :func:`written_pairs` says which."""
    pts = sim.points
    h = sim.parameters.time_step
    n = sim.n_particles
    if pts is None or len(pts.pair) == 0:
        empty = np.empty(0)
        return dict(i=np.empty(0, "i4"), j=np.empty(0, "i4"), kind=np.empty(0, "i1"), normal=np.empty((0, 2)),
                    fn=empty, ft=empty, point=np.empty((0, 2)), branch=np.empty((0, 2)), gap=empty)
    fn_pt, ft_pt = point_forces(sim.impulse, h)
    fn = _pair_sums(pts, fn_pt)
    ft = _pair_sums(pts, ft_pt)
    weight = _pair_sums(pts, np.ones_like(fn_pt))
    loaded = np.stack([_pair_sums(pts, fn_pt * pts.point[:, 0]), _pair_sums(pts, fn_pt * pts.point[:, 1])], -1)
    middle = np.stack([_pair_sums(pts, pts.point[:, 0]), _pair_sums(pts, pts.point[:, 1])], -1)
    with np.errstate(invalid="ignore", divide="ignore"):
        point = np.where((fn > 0)[:, None], loaded / fn[:, None], middle / weight[:, None])
    first = np.r_[0, np.flatnonzero(np.diff(pts.pair)) + 1]
    i = pts.body_i[first]
    j = pts.body_j[first]
    centre_i = sim.position[i]
    branch = np.where((j >= n)[:, None], point - centre_i, sim.position[np.minimum(j, n - 1)] - centre_i)
    if getattr(sim, "cell", None) is not None:  # periodic: minimum images, the point beside x_i
        branch = _nearest_image(sim.cell, branch)
        point = centre_i + _nearest_image(sim.cell, point - centre_i)
    keep = written_pairs(sim, near, n_slots)
    loaded_pair = fn > 0
    return dict(i=i[keep], j=j[keep], kind=pts.kind[first][keep], normal=pts.normal[first][keep],
                fn=np.where(loaded_pair, fn, 0.0)[keep], ft=np.where(loaded_pair, ft, 0.0)[keep],
                point=point[keep], branch=branch[keep], gap=_pair_gaps(pts)[keep])


def _nearest_image(cell, d):
    """The vectors ``d`` (P, 2) moved by whole cells to their image of fractional coordinates
    within 1/2 (:mod:`solver.periodic_detection`): the minimum image of a vector shorter than
    half the cell's widths, such as a branch or a contact point's offset from a centre."""
    t = d[:, 1] / cell.height
    n = np.rint(t)
    m = np.rint((d[:, 0] - t * cell.tilt) / cell.length)
    return np.stack([d[:, 0] - m * cell.length - n * cell.tilt, d[:, 1] - n * cell.height], -1)


# --- restart state (read back by solver.restart) -------------------------------------------
def point_impulses(sim, n_slots, near=None):
    """Normal and tangential impulses (N s) of the last step at the points of the contacts that
    :func:`pair_contacts` writes, in its slot order: two (n_slots, 2) arrays whose column 0 is
    the pair's first contact point and column 1 its second (0 for a simple contact), 0 in empty
    slots. They are the exact warm start of the next step: the resultant forces fn, ft of the
    file cannot give back the two points' impulses of a double contact, nor p = f h bit for bit.
    Pairs that are not written carry no impulse (f_n = 0 at every point, so f_t = 0 by Coulomb)."""
    normal = np.zeros((n_slots, 2))
    tangential = np.zeros((n_slots, 2))
    pts = sim.points
    if pts is None or len(pts.pair) == 0:
        return normal, tangential
    pair = pts.pair
    keep = written_pairs(sim, near, n_slots)
    slot = np.cumsum(keep) - 1
    rank = rank_in_pair(pair)
    written = keep[pair]
    normal[slot[pair[written]], rank[written]] = sim.impulse[written, 0]
    tangential[slot[pair[written]], rank[written]] = sim.impulse[written, 1]
    return normal, tangential


def wall_settings(walls):
    """Global attributes describing how each wall is driven during the recording: mode (0 fixed,
    1 imposed velocity, 2 imposed stress), stress (Pa), mass (kg), cap on the inward speed
    (m s-1) and the axis along which its length is measured (0: x, 1: y)."""
    return {"wall_mode": walls.mode.astype("i4"), "wall_mode_meanings": "fixed velocity stress",
            "wall_stress_Pa": walls.stress.astype("f8"), "wall_mass_kg": walls.mass.astype("f8"),
            "wall_max_speed_m_s": walls.max_speed.astype("f8"), "wall_length_axis": walls.length_axis.astype("i4")}


def sample_box(sim):
    """(box_min, box_max) in m written with each snapshot: the four box walls' positions
    (left, bottom, right, top) when the walls form a box; otherwise (an open scene such as
    particles on a floor) the bounding box of the particles' circumscribed disks and of the
    walls' reference points."""
    from .walls import BOX_NAMES

    if getattr(sim, "cell", None) is not None:
        return sim.cell.box()
    if set(BOX_NAMES) <= set(sim.walls.names):
        return sim.walls.box_bounds()
    r = sim.radius[:, None]
    lo = (sim.position - r).min(0)
    hi = (sim.position + r).max(0)
    if len(sim.walls):
        lo = np.minimum(lo, sim.walls.point.min(0))
        hi = np.maximum(hi, sim.walls.point.max(0))
    return lo, hi


class Recorder:
    """Stream snapshots of ``sim`` into ``path`` (context manager).

    ``near_contacts=True`` also writes the pairs within the alert distance that carry no force
    (:func:`written_pairs` with ``near = sim.alert``; attribute ``near_contacts_m``).

    Each snapshot also records the steps since the previous snapshot (since the recorder was
    made, for the first) whose NLGS did not converge, from :meth:`solver.Simulation.take_unconverged`:
    ``nlgs_unconverged_steps``, ``nlgs_unconverged_residual`` and
    ``nlgs_unconverged_local_law_residual`` (:class:`solver.stepper.Unconverged`).

    A sample with polygons has its shapes written as ``vertices`` (own-frame vertices,
    :meth:`solver.shapes.Shapes.body_vertices`), regular polygons too; a sample of disks alone
    has none.

    While the run goes on the file is netCDF-3, appended snapshot by snapshot (a killed run
    keeps every completed snapshot). When the ``with`` block ends without an exception, the
    finished file is rewritten compressed (:func:`grainview.contract.writer.compress_file`, zlib at
    ``compress``: True or a level 1-9; False, None or 0 keeps it uncompressed). A run stopped by Ctrl-C
    or an error stays netCDF-3, ready to be resumed.

    The file's writer lock (:mod:`grainview.contract.locks`) is held from before the file is created or
    read until it is closed and compressed. SIGTERM while the file is created, made netCDF-3 again
    or compressed stops at once, the file as it was (a compression stopped so leaves the
    finished run netCDF-3: :func:`compress_finished` or ``python -m solver.restart`` does it again).
    """

    def __init__(self, path, sim, attrs=None, overwrite=False, optional=OPTIONAL, near_contacts=False,
                 compress=DEFAULT_COMPLEVEL):
        self.compress = compress_level(compress)
        params = {f"solver_{k}": (v if v is not None else "none") for k, v in sim.parameters_dict().items()}
        if sim.n_walls:
            params.update(wall_settings(sim.walls))
        params.update(attrs or {})
        params["solver_version"] = __version__
        self.near = float(sim.alert) if near_contacts else None
        params["near_contacts_m"] = "none" if self.near is None else self.near
        self.sim = sim
        sim.take_unconverged()  # each snapshot counts the unconverged steps since the one before it
        periodic = sim.cell.periodic if getattr(sim, "cell", None) is not None else None
        if periodic is not None:  # the cell's rates: what a resumed run needs of a cell that moves
            optional = (*optional, "cell_velocity")
        with sigterm_raises():
            self.writer = SnapshotWriter.create(
                path, radius=sim.radius, n_vertices=sim.n_vertices, mass=sim.mass, inertia=sim.inertia,
                n_walls=sim.n_walls, wall_names=sim.walls.names, wall_normal=sim.walls.normal,
                optional=optional, attrs=params, overwrite=overwrite,
                vertices=sim.shapes.body_vertices() if sim.shapes.max_vertices else None, periodic=periodic)
        self._hold(resumable=params.get("scene") in ("biaxial", "shear"), own=True)

    @classmethod
    def append_to(cls, path, sim, compress=DEFAULT_COMPLEVEL, lock=None):
        """Go on recording ``sim`` at the end of the existing file ``path`` (a resumed run,
        :mod:`solver.restart`); the file's attributes are left as they are. A compressed file
        is made netCDF-3 again to append to, and compressed again at the end (``compress``).
        ``lock``: ``path``'s writer lock, taken by the caller before it read the state ``sim``
        comes from (the caller releases it); default: taken here.

        Raises :class:`FileFormatError`, the file untouched, when the file's last complete
        snapshot is not the state's step (``sim.step_index``): another process appended to it
        after the state was read."""
        recorder = cls.__new__(cls)
        recorder.compress = compress_level(compress)
        recorder.sim = sim
        sim.take_unconverged()
        own = lock is None
        with sigterm_raises():
            if own:
                lock = lock_file(path)
            try:
                last = last_complete_value(path, "step")
                if last is not None and last != sim.step_index:
                    raise FileFormatError(f"{path}: its last snapshot is at step {last}, not at step {sim.step_index} "
                                          "of the state to go on from (another process appended to it since the "
                                          "state was read): read the state again")
                recorder.writer = SnapshotWriter.open_append(path, lock=lock)
            except BaseException:
                if own:
                    lock.release()
                raise
        recorder._hold(resumable=True, own=own)
        near = recorder.writer.attribute("near_contacts_m", "none")
        recorder.near = None if isinstance(near, str) else float(near)
        return recorder

    def write(self):
        sim = self.sim
        n = sim.n_particles
        lo, hi = sample_box(sim)
        info = sim.last
        slots = self.writer.n_slots
        normal_impulse, tangential_impulse = point_impulses(sim, slots, self.near)
        unconverged = sim.take_unconverged()
        cell = {} if getattr(sim, "cell", None) is None else {
            "cell": sim.cell.vectors(), "cell_velocity": np.stack([np.zeros(2), sim.cell.b_rate()])}
        self.writer.append(
            time=sim.time, position=sim.position, angle=sim.angle, contacts=pair_contacts(sim, self.near, slots),
            box_min=lo, box_max=hi,
            velocity=sim.velocity[:n], angular_velocity=sim.angular_velocity[:n], wall_position=sim.walls.point,
            wall_velocity=sim.walls.velocity, normal_impulse=normal_impulse, tangential_impulse=tangential_impulse,
            wall_force=sim.wall_forces(), step=sim.step_index,
            nlgs_iterations=info.iterations if info else 0, nlgs_residual=info.residual if info else 0.0,
            local_law_residual=info.local_law_residual if info else 0.0,
            unbalanced_force=info.unbalanced_force if info else 0.0, nlgs_unconverged_steps=unconverged.steps,
            nlgs_unconverged_residual=unconverged.residual,
            nlgs_unconverged_local_law_residual=unconverged.local_law_residual,
            max_interpenetration=info.max_interpenetration if info else 0.0, kinetic_energy=sim.kinetic_energy(),
            **cell)

    def _hold(self, resumable, own):
        """Keep the writer's lock until the file is closed and compressed (released then when
        ``own``), and say in a failed write's message how to go on."""
        self._lock = self.writer.take_lock()
        self._owns_lock = own
        self.resumable = resumable
        path = shlex.quote(str(self.writer.path))
        self.writer.advice += (f", then resume it: python -m solver.restart {path}" if resumable
                               else ", then run it again, replacing the file")

    def _release(self):
        lock, self._lock = self._lock, None
        if lock is not None and self._owns_lock:
            lock.release()

    def close(self):
        """Close the file (uncompressed) and release its writer lock."""
        try:
            self.writer.close()
        finally:
            self._release()

    def __enter__(self):
        return self

    def __exit__(self, exc_type, exc, traceback):
        try:
            self.writer.close()
            if exc_type is None and self.compress:
                compress_finished(self.writer.path, self.compress, self._lock, self.resumable)
        finally:
            self._release()


def compress_finished(path, level, lock=None, resumable=True) -> None:
    """Compress the finished run ``path`` at zlib ``level`` (:func:`grainview.contract.writer.compress_file`,
    holding ``lock`` when given), SIGTERM stopping it at once. Either way the run stays
    whole: a failure (a full disk, a file-size limit) raises :class:`OutputError` in one line,
    SIGTERM prints one and raises :class:`solver.interrupt.Terminated`, and the file is left
    netCDF-3, complete; ``resumable`` (a biaxial test) says that ``python -m solver.restart``
    compresses it later."""
    later = (f"compress it later with: python -m solver.restart {shlex.quote(str(path))}" if resumable
             else "it reads as it is")
    with sigterm_raises():
        try:
            compress_file(path, level, lock=lock)
        except Terminated:
            print(f"terminated (SIGTERM) while compressing {path}: the run is complete and kept uncompressed "
                  f"(netCDF-3); {later}", file=sys.stderr)
            raise
        except OutputError as exc:
            raise OutputError(f"{path}: the run is complete but could not be compressed "
                              f"({getattr(exc, 'reason', exc)}); it is kept "
                              f"uncompressed (netCDF-3): {later}") from exc


def compress_level(compress) -> int:
    """The zlib level of a ``compress`` argument: True the default level, a level 1-9 itself,
    False, None or 0 none (0)."""
    if compress is None or compress is False:
        return 0
    if compress is True:
        return DEFAULT_COMPLEVEL
    if not (isinstance(compress, (int, np.integer)) and 0 <= compress <= 9):
        raise ParameterError(f"compress={compress!r}: expected True, False or a zlib level from 0 (none) to 9")
    return int(compress)
