"""Moreau–Jean time stepping of rigid disks and polygons between walls.

One step of length h (the theta-scheme, theta = 1/2 by default), each stage a method of
:class:`Simulation` called in turn by :meth:`Simulation.step`:

1. ``detect``: the cell-list broad phase is reused while no particle has moved more than half
   the ``skin`` since it ran; the narrow phase runs every step;
2. ``_matched_impulses``: the warm start, the previous step's impulses of the same contact
   points (matched by body pair and point rank, :meth:`Simulation._point_keys`;
   :mod:`solver.warm_start`);
3. ``_free_velocities``: v_free = v- + h M^-1 F_ext (gravity, wall stresses);
4. ``_contact_problem``: the points' geometry, Delassus data and Signorini shifts as one
   :class:`solver.nlgs.ContactProblem` (stages 1-4 together: :meth:`Simulation.contact_problem`,
   public, so that tests and benchmarks take the problem a step poses);
5. ``_solve``: the contact solver that ``Parameters.solver`` names in the registry
   :mod:`solver.contact_solvers` (the NLGS, :mod:`solver.nlgs`, or its Anderson-accelerated
   sweeps, :mod:`solver.acceleration`; either on several domains, :mod:`solver.parallel_nlgs`,
   decomposed once per step for this solve and the overlap recovery's) for the
   impulses p and the end-of-step velocities v+, then the solution's local-law residual and
   unbalanced force (:mod:`solver.residuals`) for the report;
6. ``_end_velocities``: walls driven as they are (imposed, fixed, capped);
7. ``_integrate``: x+ = x- + h [(1 - theta) v- + theta v+], likewise angles and wall
   positions, with the split-impulse removal of remaining overlaps (a second contact problem,
   solved by the same ``_solve``).

Forces are impulses divided by h. Nothing here loops over particles or contacts in Python:
each stage is one numba kernel or one vectorised numpy expression.

Each step adds the seconds of its stages to :attr:`Simulation.timings` (keys :data:`STAGES`),
the documented way to see where a step's time goes (benchmarks/step_profile.py).
"""

from __future__ import annotations

import time
import warnings
from dataclasses import asdict, dataclass, replace
from typing import NamedTuple

import numpy as np

from grainview.contract.errors import ConvergenceWarning, ParameterError

from . import (broadphase, cell_coupling, contact_solvers, narrowphase, nlgs, parallel_nlgs, periodic_assembly,
               periodic_detection, problem_assembly, residuals, warm_start)
from .contact_solvers import ContactState, Limits
from .contact_points import PairIndex, force_vectors, point_keys
from .parameters import ACCELERATIONS, MAX_FRICTION, Parameters, check_time_step  # noqa: F401 (their home)
from .sample_history import SampleHistory
from .shapes import Shapes
from .solve_records import PeriodicContactProblem, StepLaw, StepStart, StressedCellProblem
from .walls import FIXED, STRESS, VELOCITY, Walls


STAGES = ("broad_phase", "narrow_phase", "warm_start", "contact_problem", "solve", "diagnostics",
          "overlap_recovery", "update", "other")
"""The stages whose seconds :attr:`Simulation.timings` accumulates, disjoint, in the order of a
step: the broad and narrow phases of :meth:`Simulation.detect`; the warm start (the points' keys
and the matching of the last step's impulses); the contact problem (free velocities and
:meth:`Simulation._contact_problem`); the solve (the step's decomposition and its solver);
the diagnostics (the solution's local-law residual and unbalanced force); the overlap recovery
(its split-impulse solve); the update (end velocities, integration, bookkeeping); and the
step's other work (its alert distance, its record). Their sum is the time spent in
:meth:`Simulation.step` and :meth:`Simulation.contact_problem`."""


class StepProblem(NamedTuple):
    """The contact problem a step poses to its solver (:meth:`Simulation.contact_problem`).

    problem : :class:`solver.nlgs.ContactProblem`; state : :class:`solver.contact_solvers.ContactState`,
    the warm-start impulses (N s) and the free velocities (m s-1, rad s-1), fresh arrays that a
    solver may update in place; limits : :class:`solver.solve_records.Limits` of the parameters;
    points : the detected :class:`solver.narrowphase` points; keys : their identities
    (:func:`solver.contact_points.point_keys`); ra, rb : (P, 2) lever arms (m); v_start (B, 2),
    omega_start (B,): the start-of-step velocities with the imposed wall velocities.
    """

    problem: nlgs.ContactProblem
    state: ContactState
    limits: Limits
    points: object
    keys: np.ndarray
    ra: np.ndarray
    rb: np.ndarray
    v_start: np.ndarray
    omega_start: np.ndarray


@dataclass
class StepInfo:
    """What one step reports: the NLGS's sweeps and stopping norms (:mod:`solver.nlgs`),
    whether it converged, the contact points, the largest overlap (m), and two measures that
    are zero for every admissible solution (:mod:`solver.residuals`): the local-law
    (natural-map) residual |F|/|r| of the impulses, and the largest unbalanced force and
    torque on a particle over the mean impulse of a loaded point."""

    iterations: int
    residual: float
    max_residual: float
    converged: bool
    n_points: int
    max_interpenetration: float
    local_law_residual: float = 0.0
    unbalanced_force: float = 0.0
    unbalanced_torque: float = 0.0


@dataclass
class Unconverged:
    """The steps whose NLGS stopped before both its norms met their tolerances (the sweep cap
    ``max_iterations`` or the stall test of :mod:`solver.nlgs` ended it; :class:`StepInfo`
    ``converged`` False), over a span of steps: how many, and the largest of their final
    quadratic norms (the stopping norm, against ``Parameters.tolerance``) and of their local-law
    residuals |F|/|r| (:mod:`solver.residuals`; zero for every solution of the contact laws).
    Both largest values are 0 when no step is counted, and a NaN is kept."""

    steps: int = 0
    residual: float = 0.0
    local_law_residual: float = 0.0

    def add(self, info: StepInfo):
        """Count the step ``info`` (an unconverged one)."""
        self.steps += 1
        if not info.residual <= self.residual:
            self.residual = float(info.residual)
        if not info.local_law_residual <= self.local_law_residual:
            self.local_law_residual = float(info.local_law_residual)


class StepWatch:
    """Hooks of :meth:`Simulation.watch`, called around every step until :meth:`close` (or the
    end of a ``with`` block)."""

    def __init__(self, simulation, hook):
        self.simulation, self.hook = simulation, hook
        simulation._step_hooks = (*simulation._step_hooks, hook)

    def close(self):
        """Stop calling the hooks (a second call does nothing)."""
        hooks = self.simulation._step_hooks
        self.simulation._step_hooks = tuple(h for h in hooks if h is not self.hook)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False


class Simulation:
    """State of a packing (particles and walls) and its time stepping.

    Parameters
    ----------
    position : (N, 2) m, centroids; angle : (N,) rad; radius : (N,) circumscribed radius, m;
    n_vertices : (N,) 0 for disks, >= 3 for regular polygons; walls : :class:`Walls`.
    shapes : :class:`solver.shapes.Shapes`, optional
        The particles' shapes (any convex polygon, :meth:`Shapes.convex`); given, ``radius``
        and ``n_vertices`` are left out (None) and taken from it. Without it the particles are
        disks and regular polygons (:meth:`Shapes.regular` of ``radius`` and ``n_vertices``).
    cell : :class:`solver.periodic_cell.PeriodicCell`, optional
        A biperiodic cell (then ``walls`` may be None: no walls): detection finds pairs through
        their images (:mod:`solver.periodic_detection`), the problem takes body b at its image
        (:mod:`solver.periodic_assembly`), and after each step the cell moves, its height under
        its stress control, and the centres are wrapped into it (:meth:`_move_cell`).
    """

    def __init__(self, position, angle, radius=None, n_vertices=None, walls: Walls | None = None,
                 parameters: Parameters | None = None, velocity=None, angular_velocity=None,
                 shapes: Shapes | None = None, cell=None):
        p = (parameters or Parameters()).validate()
        self.parameters = p
        self.position = np.array(position, dtype=float).reshape(-1, 2)
        n = len(self.position)
        if n == 0:
            raise ParameterError("the sample is empty: expected at least one particle")
        if walls is None and cell is not None:
            walls = Walls(np.empty((0, 2)), np.empty((0, 2)))
        if walls is None:
            raise ParameterError("walls: expected the scene's Walls (solver.walls.Walls)")
        if shapes is not None:
            if not isinstance(shapes, Shapes) or len(shapes) != n:
                raise ParameterError(f"shapes: expected a solver.shapes.Shapes of the {n} particles")
            if radius is not None or n_vertices is not None:
                raise ParameterError("radius and n_vertices come from shapes when it is given: pass None for them")
            radius, n_vertices = shapes.radius, shapes.n_vertices
        self.radius = np.array(radius, dtype=float).reshape(n)
        self.n_vertices = np.array(n_vertices, dtype=np.int64).reshape(n)
        self.angle = np.zeros(n) if angle is None else np.array(angle, dtype=float).reshape(n)
        if np.any(~np.isfinite(self.position)) or np.any(~np.isfinite(self.angle)):
            raise ParameterError("positions and angles must be finite")
        if np.any(~(self.radius > 0)):
            raise ParameterError("radius must be > 0 m for every particle")
        if np.any((self.n_vertices != 0) & (self.n_vertices < 3)):
            raise ParameterError("n_vertices must be 0 (disk) or >= 3 (regular polygon)")
        self.walls = walls
        self.shapes = Shapes.regular(self.radius, self.n_vertices) if shapes is None else shapes
        self.mass, self.inertia = self.shapes.mass_and_inertia(p.density, p.thickness)
        w = len(walls)
        self.n_particles, self.n_walls = n, w
        self.velocity = np.zeros((n + w, 2))
        self.angular_velocity = np.zeros(n + w)
        if velocity is not None:
            self.velocity[:n] = velocity
        if angular_velocity is not None:
            self.angular_velocity[:n] = angular_velocity
        self.velocity[n:] = walls.velocity
        diameter = 2 * float(self.radius.min())
        self.alert = p.alert if p.alert is not None else 0.02 * diameter
        self.skin = p.skin if p.skin is not None else 0.1 * diameter
        self.time = 0.0
        self.step_index = 0
        self._anchor = None  # positions at the last broad phase
        self._wall_anchor = None  # wall positions at the last broad phase
        self.reuse_detection = True  # reuse broad-phase candidates while nothing moved skin/2
        self._candidates = None
        self._margin = 0.0  # alert + skin of the last broad phase
        self.step_alert = None  # alert distance of the current step (see alert_for_step)
        self._keys = np.empty(0, np.int64)
        self._impulse = np.empty((0, 2))
        self.points = None
        self.impulse = np.empty((0, 2))
        self.last = None
        self.history = SampleHistory()  # how the sample was made (solver.scenes, solver.preparation)
        self.timings = dict.fromkeys(STAGES, 0.0)  # seconds per stage (STAGES), summed over the steps
        self.counters = {"steps": 0, "broad_phase_runs": 0, "sweeps": 0, "point_sweeps": 0, "recovery_sweeps": 0,
                         "unconverged_steps": 0}
        self.unconverged = Unconverged()  # the unconverged steps since the last take_unconverged()
        self.cell = cell  # a PeriodicCell, or None between walls
        self.point_image = None  # periodic: (P, 2) image numbers (m, n) of body j seen from body i per point
        self.cell_stress = np.zeros((2, 2))  # periodic: the last step's contact stress (Pa), compression positive
        if cell is not None:
            self._check_cell()

    def _check_cell(self):
        """A periodic simulation's settings: no walls, a cell wide enough for detection
        (:meth:`solver.periodic_cell.PeriodicCell.check_reach`), the centres in it."""
        p = self.parameters
        if self.n_walls:
            raise ParameterError("a periodic cell has no walls (biperiodic): expected walls=None")
        self.cell.thickness = float(p.thickness)
        self.cell.check_reach(2.0 * float(self.radius.max()) + self.alert + self.skin)
        self.cell.wrap(self.position, self.velocity)

    FIXED_PARAMETERS = ("density", "thickness", "alert", "skin")
    """Parameters the simulation is built on (masses, detection distances): :meth:`set_parameters`
    refuses to change them."""

    def set_parameters(self, **changes) -> Parameters:
        """Change parameters of the running simulation (the test's friction after a
        frictionless compaction, a tolerance...): the new :class:`Parameters` are validated
        whole before they replace the old ones, which stay on a refusal. Returns them."""
        fixed = sorted(set(changes) & set(self.FIXED_PARAMETERS))
        if fixed:
            raise ParameterError(f"{', '.join(fixed)}: fixed when the simulation is built (its masses and "
                                 "detection distances); expected a new Simulation for another value")
        self.parameters = replace(self.parameters, **changes).validate()
        return self.parameters

    @property
    def preparation_attrs(self) -> dict:
        """The sample's history as file attributes (:meth:`SampleHistory.attrs`)."""
        return self.history.attrs()

    # -- mobility ---------------------------------------------------------------------------
    def _mobility(self):
        n, w = self.n_particles, self.n_walls
        minv = np.zeros((n + w, 3))
        minv[:n, 0] = minv[:n, 2] = 1.0 / self.mass
        iinv = np.zeros(n + w)
        iinv[:n] = 1.0 / self.inertia
        stress = self.walls.mode == STRESS
        nrm = self.walls.normal[stress]
        m = self.walls.mass[stress][:, None]
        minv[n:][stress] = np.stack([nrm[:, 0] ** 2, nrm[:, 0] * nrm[:, 1], nrm[:, 1] ** 2], -1) / m
        return minv, iinv

    def wall_lengths(self):
        """Length of each wall in m (the box's extent along it)."""
        lo, hi = self.walls.box_bounds()
        return np.where(self.walls.length_axis == 0, hi[0] - lo[0], hi[1] - lo[1])

    # -- detection --------------------------------------------------------------------------
    def detect(self):
        if self.cell is not None:
            return self._detect_periodic()
        start = time.perf_counter()
        moved = np.inf if self._anchor is None else float(np.sqrt(np.max(np.sum((self.position - self._anchor) ** 2, axis=1))))
        walls_moved = 0.0 if self._wall_anchor is None else float(
            np.sqrt(np.max(np.sum((self.walls.point - self._wall_anchor) ** 2, axis=1), initial=0.0)))
        alert = self.step_alert if self.step_alert is not None else self.alert
        margin = alert + self.skin
        if (moved > 0.5 * self.skin or walls_moved > 0.5 * self.skin or not self.reuse_detection
                or margin > self._margin):
            pi, pj = broadphase.candidate_pairs(self.position, self.radius, margin)
            wp, ww = broadphase.wall_candidates(self.position, self.radius, self.walls.point, self.walls.normal, margin)
            self._candidates = (pi, pj, wp, ww)
            self._anchor = self.position.copy()
            self._wall_anchor = self.walls.point.copy()
            self._margin = margin
            self.counters["broad_phase_runs"] += 1
        middle = time.perf_counter()
        pi, pj, wp, ww = self._candidates
        points = narrowphase.detect(self.position, self.angle, self.shapes, self.walls.point,
                                    self.walls.normal, alert, pi, pj, wp, ww, double_alert=self.alert,
                                    threads=self.parameters.domains)
        self.timings["broad_phase"] += middle - start
        self.timings["narrow_phase"] += time.perf_counter() - middle
        return points

    def _detect_periodic(self):
        """:meth:`detect` in the periodic cell: the broad phase of :mod:`solver.periodic_detection`,
        rerun when a centre moved (its displacement's nearest image) more than half the skin
        less half the change of b since the last run; the points with their images
        (:attr:`point_image`)."""
        start = time.perf_counter()
        cell = self.cell
        alert = self.step_alert if self.step_alert is not None else self.alert
        margin = alert + self.skin
        moved = np.inf
        if self._anchor is not None:
            d = self.position - self._anchor
            t = d[:, 1] / cell.height
            n = np.rint(t)
            m = np.rint((d[:, 0] - t * cell.tilt) / cell.length)
            dx = d[:, 0] - m * cell.length - n * cell.tilt
            dy = d[:, 1] - n * cell.height
            change = cell.vectors()[1] - self._wall_anchor
            moved = float(np.sqrt(np.max(dx * dx + dy * dy))) + 0.5 * float(np.hypot(change[0], change[1]))
        if moved > 0.5 * self.skin or not self.reuse_detection or margin > self._margin:
            pi, pj = periodic_detection.candidate_pairs(self.position, self.radius, margin, cell)
            none = np.empty(0, np.int32)
            self._candidates = (pi, pj, none, none)
            self._anchor = self.position.copy()
            self._wall_anchor = cell.vectors()[1]
            self._margin = margin
            self.counters["broad_phase_runs"] += 1
        middle = time.perf_counter()
        pi, pj = self._candidates[:2]
        points, self.point_image = periodic_detection.detect(self.position, self.angle, self.shapes, alert, pi, pj,
                                                             cell, double_alert=self.alert)
        self.timings["broad_phase"] += middle - start
        self.timings["narrow_phase"] += time.perf_counter() - middle
        return points

    def alert_for_step(self):
        """Alert distance (m) of the coming step: ``alert``, widened to what bodies can close in one step.

        A contact is seen by the solver only when its gap is <= the alert distance at the start
        of the step; a pair that closes a larger gap within the step is found already deep at
        the next one (the overlap grows with h u_n). The closing distance over a step is bounded
        by h U, with U the larger of s_1 + s_2 (the two fastest particles head on) and
        s_1 + max_walls |v_w| + h |g| (the fastest particle against a wall, with the step's
        gravity), s_i = |v_i| + |omega_i| R_i the fastest speed of a point of particle i. The step uses
        max(alert, h U), capped at half the smallest diameter; beyond the cap (bodies moving
        more than a radius per step) a RuntimeWarning asks for a smaller time step. In
        quasi-static runs h U << alert and nothing changes.
        """
        p = self.parameters
        h, n = p.time_step, self.n_particles
        speed = np.sqrt(np.sum(self.velocity[:n] ** 2, axis=1)) + np.abs(self.angular_velocity[:n]) * self.radius
        fastest = np.partition(speed, n - 2)[-2:] if n > 1 else np.r_[0.0, speed]
        wall_speed = float(np.sqrt(np.sum(self.velocity[n:] ** 2, axis=1)).max(initial=0.0))
        # the two fastest particles head on, or the fastest against the fastest wall (gravity
        # moves every particle alike: it changes only the particle-wall closing speed)
        closing = h * max(float(fastest.sum()), float(fastest[-1]) + wall_speed + h * float(np.hypot(*p.gravity)))
        if self.cell is not None:  # a pair across the boundary: the image moves with the cell
            closing = max(closing, h * (float(fastest.sum()) + float(np.hypot(*self.cell.b_rate()))))
        cap = float(self.radius.min())
        if closing > cap:
            warnings.warn(f"step {self.step_index}: bodies may close {closing:.3g} m in one step, more than the "
                          f"smallest radius {cap:.3g} m, so contacts may be missed or found deep; reduce time_step",
                          RuntimeWarning, stacklevel=3)
        return max(self.alert, min(closing, cap))

    def set_warm_start(self, i, j, normal_impulse, tangential_impulse):
        """Set the impulses that warm-start the next step (e.g. those of a file's last snapshot).

        ``i``, ``j`` (m,) are the body pairs of the contacts, ``normal_impulse`` and
        ``tangential_impulse`` (m, 2) their points' impulses in N s (column = point rank in the
        pair, as the stepper ranks them: the keys are :meth:`_point_keys`), so each impulse goes
        to the same contact point as in an uninterrupted run; a zero impulse is the same as none.
        """
        m = len(i)
        pair = np.repeat(np.arange(m), 2)
        points = PairIndex(pair=pair, body_i=np.repeat(np.asarray(i, np.int64), 2),
                           body_j=np.repeat(np.asarray(j, np.int64), 2))
        self._keys = self._point_keys(points)
        self._impulse = np.stack([np.asarray(normal_impulse, float).reshape(2 * m),
                                  np.asarray(tangential_impulse, float).reshape(2 * m)], -1)

    def show_warm_start(self):
        """Detect the contacts at the current positions and give them their warm-start
        impulses, without stepping: the contacts a snapshot written before the next step holds
        (e.g. the first snapshot of a test started from a file, :func:`solver.load_sample`).
        The next step is unchanged by it."""
        pts = self.detect()
        self.points = pts
        self.impulse = self._matched_impulses(self._point_keys(pts))

    def scale_warm_start(self, factor):
        """Multiply the warm-start impulses by ``factor`` (e.g. h_new / h_old when the time step
        changes: the same forces over a different step)."""
        self._impulse = self._impulse * float(factor)

    def _point_keys(self, pts):
        """The identity of each point across steps (:func:`solver.contact_points.point_keys`)."""
        return point_keys(pts, self.n_particles + self.n_walls)

    # -- one step ---------------------------------------------------------------------------
    def contact_problem(self) -> StepProblem:
        """The contact problem the next step will pose to its solver (stages 1-4 of the module
        docstring: the step's alert distance, detection, warm start, free velocities and
        problem), as a :class:`StepProblem`, without stepping. :meth:`step` poses its problem
        by this call, so a problem taken here is the one the next step solves, bit for bit:
        tests and benchmarks capture problems with it (detection's caches and counters move on
        as a step's would)."""
        self.step_alert = self.alert_for_step()
        pts = self.detect()
        start = time.perf_counter()
        keys = self._point_keys(pts)
        impulse = self._matched_impulses(keys)
        middle = time.perf_counter()
        v_start, omega_start, v_free, omega_free = self._free_velocities()
        problem, ra, rb = self._contact_problem(pts, v_start, omega_start)
        state = ContactState(impulse[:, 0].copy(), impulse[:, 1].copy(), v_free[:, 0].copy(), v_free[:, 1].copy(),
                             omega_free.copy())
        p = self.parameters
        limits = Limits(float(p.tolerance), float(p.max_tolerance), int(p.max_iterations), int(p.stall_sweeps))
        self.timings["warm_start"] += middle - start
        self.timings["contact_problem"] += time.perf_counter() - middle
        return StepProblem(problem, state, limits, pts, keys, ra, rb, v_start, omega_start)

    _step_hooks = ()  # (before, after) pairs of the open StepWatch-es; see watch()

    def watch(self, after=None, before=None) -> StepWatch:
        """Call ``before()`` right before every step and ``after(info)`` right after it, with the
        step's :class:`StepInfo`, until the returned :class:`StepWatch` is closed (or its
        ``with`` block ends): the documented way to observe, time or stop a run from outside
        (a benchmark counts sweeps, captures the contact problem a step is about to solve, or
        raises to end a scene there). The hooks' own time is not in :attr:`timings`. A hook that
        raises stops the run: ``before`` before the step changes anything, ``after`` once the
        step is complete. Hooks are called in the order they were added."""
        if before is None and after is None:
            raise ParameterError("watch(): expected a before() or an after(info) callable")
        for name, hook in (("before", before), ("after", after)):
            if hook is not None and not callable(hook):
                raise ParameterError(f"watch({name}={hook!r}): expected a callable")
        return StepWatch(self, (before, after))

    def step(self) -> StepInfo:
        """One Moreau–Jean step, in the stages of the module docstring; the seconds of each
        stage are added to :attr:`timings` (:data:`STAGES`). The hooks of :meth:`watch` are
        called around it."""
        hooks = self._step_hooks
        for before, _ in hooks:
            if before is not None:
                before()
        info = self._advance()
        for _, after in hooks:
            if after is not None:
                after(info)
        return info

    def _advance(self) -> StepInfo:
        """The step itself (:meth:`step` without the hooks)."""
        start = time.perf_counter()
        staged = sum(self.timings.values())
        posed = self.contact_problem()
        problem, state, pts, keys = posed.problem, posed.state, posed.points, posed.keys
        pn, pt, vx, vy, om = state
        p = self.parameters
        solve_start = time.perf_counter()
        decomposition = self._decomposition(problem)
        if self.cell is not None and self.cell.stress is not None:
            result = self._solve_with_cell(problem, state, posed.limits, shuffle=p.shuffle)
        else:
            result = self._solve(problem, state, posed.limits, shuffle=p.shuffle, decomposition=decomposition)
        converged_start = time.perf_counter()
        self.timings["solve"] += converged_start - solve_start
        converged = self._count_solve(result, len(keys))
        diagnostics_start = time.perf_counter()
        law = residuals.local_law_residual(problem, pn, pt, vx, vy, om)
        force, torque = self._unbalanced(problem, pn, pt)
        update_start = time.perf_counter()
        self.timings["diagnostics"] += update_start - diagnostics_start
        recovery = self.timings["overlap_recovery"]
        v_end, om = self._end_velocities(vx, vy, om)
        self._integrate(pts, problem, posed.ra, posed.rb, posed.v_start, posed.omega_start, v_end, om, decomposition)
        if self.cell is not None:
            self._move_cell(problem, pn, pt)
        self.points = pts
        self.impulse = np.stack([pn, pt], -1)
        self._keys, self._impulse = keys, self.impulse
        self.time += p.time_step
        self.step_index += 1
        self.counters["steps"] += 1
        overlap = float(max(0.0, -pts.gap.min())) if len(pts.gap) else 0.0
        self.last = StepInfo(result.iterations, result.residual, result.max_residual, converged, len(keys), overlap,
                             law, force, torque)
        if not converged:
            self.counters["unconverged_steps"] += 1
            self.unconverged.add(self.last)
        end = time.perf_counter()
        self.timings["update"] += end - update_start - (self.timings["overlap_recovery"] - recovery)
        self.timings["other"] += (end - start) - (sum(self.timings.values()) - staged)
        return self.last

    def take_unconverged(self) -> Unconverged:
        """The :class:`Unconverged` steps since the previous call (or since the simulation was
        made), and a new count from here: what a snapshot records of the steps since the one
        before it (:class:`solver.output.Recorder`)."""
        taken, self.unconverged = self.unconverged, Unconverged()
        return taken

    def _unbalanced(self, problem, pn, pt):
        """(force, torque) ratios of :func:`solver.residuals.unbalanced_ratios`, gravity the
        particles' external impulse h m g."""
        p = self.parameters
        external = p.time_step * self.mass[:, None] * np.asarray(p.gravity, dtype=float)
        return residuals.unbalanced_ratios(problem, pn, pt, external, self.radius)

    def _matched_impulses(self, keys):
        """Warm start: the last step's impulses (P, 2) of the same contact points (keys of
        :meth:`_point_keys`), 0 for new points (:func:`solver.warm_start.match_impulses`)."""
        return warm_start.match_impulses(self._keys, self._impulse, keys)

    def _free_velocities(self):
        """Start-of-step velocities (bodies, 2) and (bodies,) with the imposed wall velocities,
        and the free velocities v- + h M^-1 F_ext (gravity on particles, stress on pushed walls)."""
        p = self.parameters
        h, n = p.time_step, self.n_particles
        v_start = self.velocity.copy()
        omega_start = self.angular_velocity.copy()
        v = v_start.copy()
        omega = omega_start.copy()
        velocity_walls = np.flatnonzero(self.walls.mode == VELOCITY)
        v[n + velocity_walls] = self.walls.velocity[velocity_walls]
        v_start[n + velocity_walls] = self.walls.velocity[velocity_walls]
        if p.gravity[0] != 0.0 or p.gravity[1] != 0.0:
            v[:n] += h * np.asarray(p.gravity)
        stress_walls = np.flatnonzero(self.walls.mode == STRESS)
        if stress_walls.size:
            force = (self.walls.stress * self.wall_lengths() * p.thickness)[stress_walls, None] * self.walls.normal[stress_walls]
            v[n + stress_walls] += h * force / self.walls.mass[stress_walls, None]
        return v_start, omega_start, v, omega

    def _contact_problem(self, pts, v_start, omega_start):
        """The step's :class:`solver.nlgs.ContactProblem` from the detected points, and the
        lever arms ra, rb (P, 2) m (:func:`solver.problem_assembly.assemble`: the Signorini
        shift comes from the gaps predicted to mid-step with the start velocities)."""
        p = self.parameters
        centre = np.concatenate([self.position, self.walls.point])
        if self.cell is not None:
            return self._periodic_problem(pts, centre, v_start, omega_start)
        a, b, ra, rb, nx, ny, bias, mu = problem_assembly.assemble(
            pts, StepStart(centre, v_start, omega_start, self.n_particles),
            StepLaw(float(p.time_step), float(p.theta), float(p.friction), float(p.wall_friction)))
        minv, iinv = self._mobility()
        problem = nlgs.ContactProblem(
            a, b, nx, ny, ra[:, 0].copy(), ra[:, 1].copy(), rb[:, 0].copy(), rb[:, 1].copy(), bias, mu,
            minv[:, 0].copy(), minv[:, 1].copy(), minv[:, 2].copy(), iinv)
        return problem, ra, rb

    def _periodic_problem(self, pts, centre, v_start, omega_start):
        """:meth:`_contact_problem` in the periodic cell: body b at its image
        (:mod:`solver.periodic_assembly`), a :class:`PeriodicContactProblem`."""
        p = self.parameters
        images = periodic_assembly.Images(self.cell.image_shifts(self.point_image),
                                          self.cell.image_velocities(self.point_image))
        self._images = images
        a, b, ra, rb, nx, ny, bias, mu, slip = periodic_assembly.assemble(
            pts, images, StepStart(centre, v_start, omega_start, self.n_particles),
            StepLaw(float(p.time_step), float(p.theta), float(p.friction), float(p.wall_friction)))
        minv, iinv = self._mobility()
        problem = PeriodicContactProblem(
            a, b, nx, ny, ra[:, 0].copy(), ra[:, 1].copy(), rb[:, 0].copy(), rb[:, 1].copy(), bias, mu,
            minv[:, 0].copy(), minv[:, 1].copy(), minv[:, 2].copy(), iinv, slip)
        return problem, ra, rb

    def _solve_with_cell(self, problem, state: ContactState, limits: Limits, shuffle=False):
        """The periodic problem with the cell's height rate as one more unknown, under its normal
        stress (:mod:`solver.cell_coupling`), by the NLGS or Anderson sweeps on one domain; the
        rate is kept in :attr:`cell_rate` for :meth:`_move_cell`. Returns the method's
        :class:`solver.nlgs.NLGSResult`."""
        p = self.parameters
        cell = self.cell
        contact_solvers.check_cell_coupling(p)
        load = float(p.time_step) * cell.stress * cell.length * float(p.thickness)
        stressed = StressedCellProblem(*problem, self.point_image[:, 1].astype(np.float64),
                                       np.array([cell.height_rate, cell.height_rate, cell.mass, load]))
        method = contact_solvers.method(p.solver)
        options = method.options(p, x=self.position[:self.n_particles, 0], shuffle=shuffle,
                                 seed=p.seed + self.step_index)
        if "domains" in options:
            options["domains"] = 1
        result = method.solve(stressed, state, limits, **options)
        self.cell_rate = float(stressed.cell[cell_coupling.RATE])
        smallest = float(self.radius[:self.n_particles].min())
        if not abs(self.cell_rate) * float(p.time_step) <= smallest:
            raise ParameterError(f"the periodic cell's height would change by {self.cell_rate * p.time_step:.4g} m at "
                                 f"step {self.step_index}, more than the smallest grain's radius {smallest:.4g} m in one "
                                 f"step: its stress control diverged with a cell mass of {cell.mass:.4g} kg (expected "
                                 "a larger cell mass or a smaller time step)")
        return result

    def _move_cell(self, problem, pn, pt):
        """After a periodic step: the contact stress of its impulses over the cell's volume
        (:attr:`cell_stress`), the cell moved over the step at its new height rate (the one
        solved with the points under stress control, :meth:`_solve_with_cell`), the particles'
        velocities following the change of the cell's rate
        (:meth:`~solver.periodic_cell.PeriodicCell.follow_rate`), and the centres that left the
        cell wrapped into it with their velocities."""
        p = self.parameters
        h = float(p.time_step)
        sums = periodic_assembly.stress_sums(problem, pn, pt, h)
        self.cell_stress = sums / (self.cell.area() * p.thickness)
        before = self.cell.b_rate()
        if self.cell.stress is not None:
            self.cell.set_height_rate(self.cell_rate)
        self.cell.advance(h)
        self.cell.follow_rate(self.position, self.velocity, self.cell.b_rate() - before)
        self.cell.wrap(self.position, self.velocity)

    def _count_solve(self, result, n_points):
        """Count the sweeps (a solver's iterations); warn (ConvergenceWarning) when the iteration
        cap or a stall test stopped the solver before both norms were met. Returns whether it
        converged."""
        p = self.parameters
        self.counters["sweeps"] += result.iterations
        self.counters["point_sweeps"] += result.iterations * n_points
        converged = result.residual <= p.tolerance and result.max_residual <= p.max_tolerance
        if not converged:
            m = contact_solvers.method(p.solver)
            if result.iterations >= p.max_iterations:
                stop = f"the {m.iteration} cap"
            else:
                stop = contact_solvers.stall_rule(p.solver, p.stall_sweeps) or "a stall"
            warnings.warn(f"the contact solver ({p.solver}) did not converge at step {self.step_index} (t = "
                          f"{self.time:.6g} s): stopped by {stop} after {result.iterations} {m.iteration}s, residual "
                          f"{result.residual:.3g} (tolerance {p.tolerance:g}), max residual "
                          f"{result.max_residual:.3g} (tolerance {p.max_tolerance:g})", ConvergenceWarning,
                          stacklevel=3)
        return converged

    def _end_velocities(self, vx, vy, om):
        """End-of-step velocities from the solution: imposed walls keep their velocity, fixed
        walls stay at rest, pushed walls are capped at their ``max_speed`` inwards, and no
        wall rotates."""
        n = self.n_particles
        v_end = np.stack([vx, vy], -1)
        velocity_walls = np.flatnonzero(self.walls.mode == VELOCITY)
        v_end[n + velocity_walls] = self.walls.velocity[velocity_walls]
        fixed = np.flatnonzero(self.walls.mode == FIXED)
        v_end[n + fixed] = 0.0
        stress_walls = np.flatnonzero(self.walls.mode == STRESS)
        if stress_walls.size:  # cap the inward speed of pushed walls (closing a loose sample)
            inward = np.sum(v_end[n + stress_walls] * self.walls.normal[stress_walls], axis=1)
            excess = np.maximum(inward - self.walls.max_speed[stress_walls], 0.0)
            v_end[n + stress_walls] -= excess[:, None] * self.walls.normal[stress_walls]
        om[n:] = 0.0
        return v_end, om

    def _integrate(self, pts, problem, ra, rb, v_start, omega_start, v_end, om, decomposition=None):
        """theta-scheme update of positions, angles and walls, with the split-impulse removal of
        remaining overlaps (:meth:`_recover_overlaps`, on the step's ``decomposition``); stores
        the end velocities."""
        p = self.parameters
        h, theta, n = p.time_step, p.theta, self.n_particles
        a = problem.a
        step_v = (1 - theta) * v_start + theta * v_end
        step_om = (1 - theta) * omega_start + theta * om
        if p.overlap_recovery_speed > 0 and len(a):
            # the end-of-step gaps (first order) tell which overlaps remain
            g_end = problem_assembly.end_gaps(pts, problem, step_v, step_om, h)
            if self.cell is not None:  # the image moved with the cell
                g_end = g_end + h * np.sum(self._images.velocity * pts.normal, axis=1)
            if g_end.min() < -p.overlap_recovery_threshold * 2 * float(self.radius.min()):
                pseudo_v, pseudo_om = self._recover_overlaps(problem, g_end, decomposition)
                pseudo_v[n + np.flatnonzero(self.walls.mode != STRESS)] = 0.0
                step_v = step_v + pseudo_v
                step_om = step_om + pseudo_om
        self.position += h * step_v[:n]
        self.angle += h * step_om[:n]
        self.walls.point += h * step_v[n:]
        stress_walls = np.flatnonzero(self.walls.mode == STRESS)
        self.walls.velocity[stress_walls] = v_end[n + stress_walls]
        self.velocity = v_end
        self.angular_velocity = om

    def _decomposition(self, problem):
        """The step's :func:`solver.parallel_nlgs.decompose` of ``problem`` on the parameters'
        domains (None on one domain): made once, for the main solve and the overlap recovery's
        (same points, bodies and particle positions)."""
        if self.parameters.domains <= 1:
            return None
        return parallel_nlgs.decompose(problem, self.position[:self.n_particles, 0], self.parameters.domains)

    def _solve(self, problem, state: ContactState, limits: Limits, shuffle=False, decomposition=None):
        """Solve a contact problem in place (``state`` updated) by the method of the registry
        :mod:`solver.contact_solvers` that ``Parameters.solver`` names, with its options from
        the parameters (:meth:`solver.contact_solvers.Method.options`): on the step's
        ``decomposition`` when it has domains, in a random order (seeded by the seed and the
        step index) when ``shuffle`` and it has one. Returns its
        :class:`solver.nlgs.NLGSResult`."""
        p = self.parameters
        method = contact_solvers.method(p.solver)
        options = method.options(p, x=self.position[:self.n_particles, 0], decomposition=decomposition,
                                 shuffle=shuffle, seed=p.seed + self.step_index)
        return method.solve(problem, state, limits, **options)

    def _recover_overlaps(self, problem, g_end, decomposition=None):
        """Split-impulse removal of overlaps: pseudo-velocities that move the bodies apart at
        most at ``overlap_recovery_speed``, removing ``overlap_recovery_rate`` of each overlap
        per step, frictionless, added to the positions only. The real velocities (momentum,
        kinetic energy) are untouched, so existing overlaps are removed gently and never
        pushed out explosively. ``decomposition``: the step's (:meth:`_decomposition`). Returns
        the pseudo-velocities (bodies, 2) and (bodies,)."""
        start = time.perf_counter()
        p = self.parameters
        h = p.time_step
        recover = np.minimum(p.overlap_recovery_rate * np.maximum(-g_end, 0.0) / h, p.overlap_recovery_speed)
        m = len(problem.a)
        recovery = problem._replace(bias=np.where(g_end >= 0.0, g_end / h, -recover), mu=np.zeros(m))
        bodies = self.n_particles + self.n_walls
        state = ContactState(np.zeros(m), np.zeros(m), np.zeros(bodies), np.zeros(bodies), np.zeros(bodies))
        limits = Limits(float(p.overlap_recovery_tolerance), 1.0, int(p.overlap_recovery_iterations), 0)
        result = self._solve(recovery, state, limits, decomposition=decomposition)
        self.counters["recovery_sweeps"] += result.iterations
        self.timings["overlap_recovery"] += time.perf_counter() - start
        return np.stack([state.vx, state.vy], -1), state.w

    # -- derived quantities ------------------------------------------------------------------
    def kinetic_energy(self):
        """Kinetic energy of the particles in J."""
        n = self.n_particles
        return float(0.5 * np.sum(self.mass * np.sum(self.velocity[:n] ** 2, axis=1))
                     + 0.5 * np.sum(self.inertia * self.angular_velocity[:n] ** 2))

    def wall_forces(self):
        """(W, 2) total force exerted by the particles on each wall in N, from the last step."""
        out = np.zeros((self.n_walls, 2))
        if self.points is None or not len(self.points.gap):
            return out
        pts = self.points
        f = force_vectors(pts.normal, self.impulse, self.parameters.time_step)
        on_wall = pts.body_j >= self.n_particles
        np.add.at(out, pts.body_j[on_wall] - self.n_particles, f[on_wall])
        return out

    def wall_stresses(self):
        """Normal stress exerted by the particles on each wall, Pa (force / length / thickness)."""
        f = self.wall_forces()
        normal_force = -np.sum(f * self.walls.normal, axis=1)
        return normal_force / (self.wall_lengths() * self.parameters.thickness)

    def parameters_dict(self):
        d = asdict(self.parameters)
        d.update(alert=self.alert, skin=self.skin)
        return d


def _history_alias(name):
    """``sim.<name>``: ``sim.history.<name>`` (:class:`SampleHistory`), read-only, for the scripts
    that read the sample's history from the simulation; the history is written in
    ``sim.history`` alone."""
    return property(lambda self: getattr(self.history, name),
                    doc=f"``history.{name}`` (:class:`solver.sample_history.SampleHistory`), read-only.")


for _name in ("sigma0", "settled", "compaction_steps", "compaction_stress", "compaction_inertia_number",
              "compaction_unconverged", "preparation"):
    setattr(Simulation, _name, _history_alias(_name))
del _name
