"""The one registry of the methods that solve a frictional contact problem, by name.

It lists only methods a user can choose: by ``Parameters.solver`` (the command line's
``--solver``) for the stepper's problem, by ``solve_contact_problem(method=)`` for a problem given
by its matrix. Experiments that no user path reaches are not registered; they live outside the
solver, in benchmarks/research/.

A method registers once (:func:`register`) as a :class:`Method`, with a status (one of
:data:`STATUSES`: ``default``, the stepper's method unless another is chosen, exactly one;
``alternative``, a method to choose for a reason the docs give; ``experimental``, kept to be
studied, with a known limit) and one or both of two entry points, declared by their signatures
(:class:`StepperSolve`, :class:`MatrixSolve`; :func:`register` refuses an entry point whose
parameters differ):

``solve(problem, state, limits, **options) -> NLGSResult`` (the stepper's problem)
    ``problem`` the time step's :class:`solver.nlgs.ContactProblem`; ``state`` a
    :class:`ContactState`, the warm-start impulses and the free body velocities, updated in
    place to the solution; ``limits`` a :class:`solver.solve_records.Limits` (the two NLGS
    norms' tolerances, the sweep cap, the stall test's sweeps);
    ``options`` the method's own keywords, read from :class:`solver.stepper.Parameters` by
    :meth:`Method.options`. The result is a :class:`solver.nlgs.NLGSResult`: iterations, and
    the quadratic and max norms of the NLGS stopping test (:mod:`solver.nlgs`), which the
    stepper compares with ``Parameters.tolerance`` and ``max_tolerance``. A method with this
    entry can be chosen by ``Parameters.solver`` (and the command line's ``--solver``).
``solve_matrix(W, q, mu, tolerance, max_iterations, initial, **options) -> ContactSolution`` (a matrix problem)
    u = W r + q given by its Delassus matrix (:func:`solver.contact_problem.solve_contact_problem`
    validates it and dispatches here): W (2n, 2n) CSR with sorted indices, q (2n,), mu (n,),
    ``initial`` (n, 2) starting impulses; the result a
    :class:`solver.contact_solution.ContactSolution`.

The methods registered here:

``nlgs`` (alternative)
    Point-by-point nonlinear Gauss–Seidel (:mod:`solver.nlgs`). In the stepper: the serial
    sweep, in a random order when ``Parameters.shuffle``, or the domain-decomposed sweeps of
    :mod:`solver.parallel_nlgs` when ``Parameters.domains`` > 1. On a matrix
    (:func:`solver.nlgs.solve_matrix`): ``tolerance`` its quadratic norm, ``max_tolerance`` (an
    option, default 60 x ``tolerance``) its max norm, ``max_iterations`` the sweep cap.
``anderson`` (default)
    NLGS sweeps combined by Anderson extrapolation (:mod:`solver.acceleration`; the stepper's
    default), ``Parameters.anderson_memory`` past sweeps every ``anderson_period`` sweeps, on
    ``domains`` domains; no shuffled order. Stepper only.
``newton`` (experimental)
    Semi-smooth Newton on Alart–Curnier's function with a line search
    (:mod:`solver.nonsmooth_newton`); ``tolerance`` is the local-law residual
    (:mod:`solver.contact_solution`). Matrix only.
``pcg`` (experimental)
    Projected conjugate gradient after Renouf & Alart (:mod:`solver.projected_cg`);
    ``tolerance`` is the local-law residual. In the stepper it solves the step's problem in
    matrix form (:mod:`solver.matrix_form`: W and q assembled every step, the velocities
    updated from the impulses), from the warm start, until the local-law residual
    (:mod:`solver.residuals`) is within ``Parameters.tolerance`` or ``max_iterations``
    iterations; both norms of its result are that residual. One domain, no random order, no
    stall test of the NLGS's (its own: :data:`solver.projected_cg.STALL_ITERATIONS`). A known
    limit: where W is singular (more points than the bodies' degrees of freedom, as in a
    compacted packing with frictionless walls) its projections can stall far from the
    tolerance on steps that the NLGS solves in a few sweeps; such a step is reported
    unconverged (a ConvergenceWarning) with its true residual. An alternative to study, not
    a default.

:data:`ACCELERATIONS` maps the values of the former ``acceleration`` setting (``off``,
``anderson``; files and scripts written before ``Parameters.solver``) to the methods they name.

Adding a method: write its entry point(s) with the signatures above in a module of its own,
and add one ``register(Method(...))`` below, saying its status, which ``Parameters`` fields it
reads as options (``parameters``), whether it runs on several domains (``domains``), whether it
visits points in a random order (``shuffle``) and whether it applies the NLGS's stall test
(``stall``). The stepper, ``Parameters.validate``, the command line's choices and their
help (:func:`choices_help`) and restart read the registry and need no edit; add its row to the
table of docs/solver.md (tests/solver/test_solver_docs.py compares the two);
tests/solver/test_physics.py runs every stepper method on its analytic scenes.

This module imports numpy and the contract's errors only (each entry point imports its
solver's module when called), so the command line and :mod:`solver.parameters` read the
registry's names without loading a compiled kernel.
"""

from __future__ import annotations

import importlib
import inspect
from dataclasses import dataclass
from typing import TYPE_CHECKING, Callable, NamedTuple, Protocol

import numpy as np

from grainview.contract.errors import ParameterError

from .solve_records import Impulses, Limits, MatrixProblem

if TYPE_CHECKING:  # the results' types, named in the signatures only
    from .contact_solution import ContactSolution
    from .nlgs import NLGSResult

__all__ = ["ACCELERATIONS", "STATUSES", "ContactState", "Limits", "MatrixSolve", "Method", "StepperSolve",
           "choices", "choices_help", "default_method", "matrix_methods", "method", "register", "solver",
           "solve_nlgs", "stepper_methods"]

STATUSES = ("default", "alternative", "experimental")
"""What a registered method is to a user, in the order the choices are listed (module docstring)."""


class ContactState(NamedTuple):
    """What a stepper method updates in place: the impulses ``pn, pt`` (P,) in N s (warm start on
    entry) and the bodies' velocities ``vx, vy`` (B,) m s-1 and ``w`` (B,) rad s-1 (the free
    velocities on entry, the end-of-step ones on return)."""

    pn: np.ndarray
    pt: np.ndarray
    vx: np.ndarray
    vy: np.ndarray
    w: np.ndarray


class StepperSolve(Protocol):
    """The stepper's entry point (module docstring): the step's problem, its state updated in
    place, its limits, and the method's own options as keywords."""

    def __call__(self, problem, state: ContactState, limits: Limits, **options) -> NLGSResult: ...


class MatrixSolve(Protocol):
    """The matrix entry point (module docstring): u = W r + q, the friction, the tolerance, the
    iteration cap and the starting impulses, and the method's own options as keywords."""

    def __call__(self, W, q, mu, tolerance, max_iterations, initial, **options) -> ContactSolution: ...


def _positional(protocol) -> tuple:
    """The names of the positional parameters of ``protocol``'s ``__call__`` (``self`` aside)."""
    return tuple(name for name, p in inspect.signature(protocol.__call__).parameters.items()
                 if p.kind is p.POSITIONAL_OR_KEYWORD and name != "self")


def signature_problems(entry, protocol) -> list:
    """How the callable ``entry`` differs from the declared signature ``protocol``
    (:class:`StepperSolve` or :class:`MatrixSolve`): its positional parameters must be the
    protocol's, in order, and every other parameter a keyword with a default (an option)."""
    expected, bad = _positional(protocol), []
    parameters = list(inspect.signature(entry).parameters.values())
    positional = tuple(p.name for p in parameters if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)
                       and p.default is p.empty)
    if positional != expected:
        bad.append(f"takes ({', '.join(positional)}) where {protocol.__name__} takes ({', '.join(expected)})")
    loose = [p.name for p in parameters if p.name not in expected and p.kind is not p.VAR_KEYWORD
             and p.default is p.empty]
    if loose:
        bad.append(f"options without a default: {', '.join(loose)}")
    return bad


@dataclass(frozen=True)
class Method:
    """One registered way of solving (module docstring).

    name : the name ``Parameters.solver``, ``--solver`` and ``solve_contact_problem(method=)``
        take; summary : one line saying what it is (the command line's help).
    status : one of :data:`STATUSES`.
    solve : the stepper entry point (:class:`StepperSolve`), or None (matrix problems only).
    solve_matrix : the matrix entry point (:class:`MatrixSolve`), or None (the stepper's
        problem only).
    parameters : ((Parameters field, option keyword), ...) that :meth:`options` passes to ``solve``.
    domains : whether ``solve`` runs on several domains (options ``domains``, ``x``: the
        particles' abscissae in m, ``decomposition``: :func:`solver.parallel_nlgs.decompose`).
    shuffle : whether ``solve`` can visit the points in a random order (options ``shuffle``,
        ``seed``).
    stall : whether ``solve`` applies the NLGS's stall test (``limits.stall``,
        ``Parameters.stall_sweeps``).
    label : its short name in reports' prose ("NLGS convergence: ...").
    iteration : what one of its iterations is called ("sweep", "iteration").
    norms : what its tolerances apply to, as the words after "before" in a report.
    own_stall : a function of no argument returning the words for its own stall test, for a
        method without the NLGS's (None for none); called when the words are needed, so that
        the registry imports no method's module.
    couples_cell : whether ``solve`` sweeps a stress-controlled periodic cell's rate with the
        contacts (:func:`solver.cell_coupling.couple_cell`): only such a method solves the
        periodic shear under a normal stress.
    """

    name: str
    summary: str
    status: str
    solve: Callable | None = None
    solve_matrix: Callable | None = None
    parameters: tuple = ()
    domains: bool = False
    shuffle: bool = False
    stall: bool = True
    label: str = "NLGS"
    iteration: str = "sweep"
    norms: str = "both stopping norms (the impulses' change over a sweep) met their tolerances"
    own_stall: Callable | None = None
    couples_cell: bool = False

    @property
    def in_stepper(self) -> bool:
        """Whether the time stepper can use it."""
        return self.solve is not None

    def options(self, parameters, *, x=None, decomposition=None, shuffle=False, seed=0) -> dict:
        """The keyword options of ``solve`` for the :class:`solver.stepper.Parameters`
        ``parameters``: the fields of ``self.parameters``, and, where the method takes them,
        the domains with the particles' abscissae ``x`` and the step's ``decomposition``, and
        the random order (``shuffle``, ``seed``)."""
        options = {keyword: getattr(parameters, field) for field, keyword in self.parameters}
        if self.domains:
            options.update(domains=parameters.domains, x=x, decomposition=decomposition)
        if self.shuffle:
            options.update(shuffle=shuffle, seed=seed)
        return options

    def problems(self, parameters) -> list:
        """What in ``parameters`` (:class:`solver.parameters.Parameters`) this stepper method
        cannot run with, one 'name=value: expected ...' string each (empty when it can)."""
        bad = []
        if parameters.domains != 1 and not self.domains:
            bad.append(f"domains={parameters.domains!r}: expected 1 with solver={self.name!r} (it has no "
                       "domain-decomposed sweeps)")
        if parameters.shuffle and not self.shuffle:
            bad.append(f"shuffle={parameters.shuffle!r}: expected False with solver={self.name!r} (the random order "
                       f"is an option of {', '.join(n for n, m in _METHODS.items() if m.shuffle)})")
        if parameters.stall_sweeps and not self.stall:
            bad.append(f"stall_sweeps={parameters.stall_sweeps!r}: expected 0 with solver={self.name!r} (it has no "
                       "stall test of the NLGS's)")
        if parameters.shuffle and parameters.domains != 1:
            bad.append(f"domains={parameters.domains!r}: expected 1 with shuffle (the domain-decomposed sweep has "
                       "its own order)")
        return bad


_METHODS: dict[str, Method] = {}

ACCELERATIONS = {"off": "nlgs", "anderson": "anderson"}
"""The former ``acceleration`` setting's values -> the method each names."""


def register(entry: Method) -> Method:
    """Add ``entry`` to the registry under its name (once: a second method of the same name is
    refused), after checking its status, its entry points' signatures and, for a stepper
    method with status ``default``, that it is the only one. Returns it."""
    if entry.name in _METHODS:
        raise ValueError(f"a contact solver named {entry.name!r} is already registered")
    if entry.solve is None and entry.solve_matrix is None:
        raise ValueError(f"{entry.name!r}: a method needs a stepper entry (solve) or a matrix one (solve_matrix)")
    if entry.status not in STATUSES:
        raise ValueError(f"{entry.name!r}: status={entry.status!r}, expected one of {', '.join(STATUSES)}")
    if entry.status == "default":
        other = next((name for name, m in _METHODS.items() if m.status == "default"), None)
        if entry.solve is None or other is not None:
            raise ValueError(f"{entry.name!r}: the default is one stepper method" + (f" ({other!r} is)" if other else ""))
    bad = [f"{kind} {problem}" for kind, function, protocol in (("solve", entry.solve, StepperSolve),
                                                                ("solve_matrix", entry.solve_matrix, MatrixSolve))
           if function is not None for problem in signature_problems(function, protocol)]
    if bad:
        raise ValueError(f"{entry.name!r}: " + "; ".join(bad))
    _METHODS[entry.name] = entry
    return entry


def default_method() -> str:
    """The name of the stepper's default method (status ``default``)."""
    return next(name for name, m in _METHODS.items() if m.status == "default")


def choices() -> tuple:
    """((name, status, summary), ...) of the methods the time stepper can use, the default first,
    then by status (:data:`STATUSES`) and name: the command line's ``--solver`` choices."""
    return tuple(sorted(((name, m.status, m.summary) for name, m in _METHODS.items() if m.in_stepper),
                        key=lambda c: (STATUSES.index(c[1]), c[0])))


def choices_help() -> str:
    """The stepper's methods with their status and summary, in words, for the help of
    ``--solver``: "'anderson' (default): Anderson-accelerated ...; 'nlgs' (alternative): ..."."""
    return "; ".join(f"{name!r} ({status}): {summary}" for name, status, summary in choices())


def stepper_methods() -> tuple:
    """The names of the methods the time stepper can use, sorted."""
    return tuple(sorted(name for name, m in _METHODS.items() if m.in_stepper))


def cell_coupling_methods() -> tuple:
    """The names of the stepper methods that sweep a stress-controlled periodic cell's rate with
    the contacts (``couples_cell``), sorted."""
    return tuple(sorted(name for name, m in _METHODS.items() if m.in_stepper and m.couples_cell))


def check_cell_coupling(parameters):
    """Refuse, in one line, a stepper solver (``parameters.solver``) that cannot sweep a
    stress-controlled periodic cell's rate with the contacts (:func:`cell_coupling_methods`)."""
    solvers = cell_coupling_methods()
    if parameters.solver not in solvers:
        raise ParameterError(f"solver={parameters.solver!r}: a periodic cell under a normal stress is solved by "
                             f"{' or '.join(solvers)} (its height's rate is swept with the contacts)")


def matrix_methods() -> tuple:
    """The names of the methods that solve a problem given by its matrix, sorted."""
    return tuple(sorted(name for name, m in _METHODS.items() if m.solve_matrix is not None))


def method(name: str) -> Method:
    """The method registered as ``name``; a ParameterError naming the registered ones otherwise."""
    try:
        return _METHODS[name]
    except (KeyError, TypeError):
        raise ParameterError(f"solver={name!r}: expected one of {', '.join(stepper_methods())} (the time "
                             f"stepper's); problems given by their matrix: {', '.join(matrix_methods())}") from None


def stall_rule(name: str, stall_sweeps=None) -> str:
    """The stall test that stops the method ``name``, in words ("" for none): the NLGS's when the
    method applies it and ``stall_sweeps`` > 0 (the best quadratic norm down by less than 5% over
    that many sweeps), otherwise the method's own, if it has one."""
    from .solve_records import STALL_IMPROVEMENT

    m = method(name)
    if m.stall:
        return (f"the stall test (quadratic norm down by < {100 * STALL_IMPROVEMENT:g}% over {stall_sweeps:.0f} "
                "sweeps)") if stall_sweeps else ""
    return m.own_stall() if m.own_stall is not None else ""


def stop_rule(name: str, max_iterations=None, stall_sweeps=None) -> str:
    """What stops the method ``name`` short of its tolerances, in words: its iteration cap
    (``max_iterations`` of them, where given) and its stall test (:func:`stall_rule`). Reports
    and warnings take the words from here."""
    m = method(name)
    cap = f"the {m.iteration} cap" + (f" ({max_iterations:.0f} {m.iteration}s)" if max_iterations else "")
    stall = stall_rule(name, stall_sweeps)
    return f"{cap} or {stall}" if stall else cap


def from_acceleration(value: str) -> str:
    """The method named by a value of the former ``acceleration`` setting (:data:`ACCELERATIONS`);
    a ParameterError naming the accepted values otherwise."""
    try:
        return ACCELERATIONS[value]
    except (KeyError, TypeError):
        raise ParameterError(f"acceleration={value!r}: expected one of {', '.join(ACCELERATIONS)} (or solver= one "
                             f"of {', '.join(stepper_methods())})") from None


def acceleration_of(name: str) -> str | None:
    """The former ``acceleration`` value that names the method ``name`` (None for a method it
    had no value for)."""
    return next((value for value, named in ACCELERATIONS.items() if named == name), None)


def solver(name: str):
    """The matrix entry point of the method registered as ``name``; a ParameterError naming the
    methods that have one otherwise (:func:`solver.contact_problem.solve_contact_problem`)."""
    entry = _METHODS.get(name) if isinstance(name, str) else None
    if entry is None or entry.solve_matrix is None:
        raise ParameterError(f"method={name!r}: expected one of {', '.join(matrix_methods())}")
    return entry.solve_matrix


# -- the registered methods ------------------------------------------------------------------

def solve_nlgs(W, q, mu, tolerance, max_iterations, initial, *, max_tolerance=None) -> ContactSolution:
    """NLGS sweeps (:func:`solver.nlgs.solve_matrix`) until the quadratic norm is within
    ``tolerance`` and the max norm within ``max_tolerance`` (default 60 x ``tolerance``, about
    the time stepper's ratio), or ``max_iterations`` sweeps."""
    from . import nlgs
    from .contact_solution import contact_solution

    if max_tolerance is None:
        max_tolerance = 60.0 * tolerance
    if not (np.isfinite(max_tolerance) and max_tolerance > 0):
        raise ParameterError(f"max_tolerance={max_tolerance!r}: expected a positive number")
    rn, rt = initial[:, 0].copy(), initial[:, 1].copy()
    matrix = MatrixProblem(W.indptr.astype(np.int64), W.indices.astype(np.int64), W.data, q, mu)
    iterations, quad, worst = nlgs.solve_matrix(matrix, Impulses(rn, rt),
                                                Limits(float(tolerance), float(max_tolerance), int(max_iterations), 0))
    converged = bool(quad <= tolerance and worst <= max_tolerance)
    return contact_solution(W, q, mu, np.stack([rn, rt], -1), iterations, converged, quad, worst)


def solve_stepper_nlgs(problem, state: ContactState, limits: Limits, *, domains=1, x=None, decomposition=None,
                       shuffle=False, seed=0) -> NLGSResult:
    """The stepper's problem by NLGS sweeps: serial (:func:`solver.nlgs.solve_problem`, in a
    random order seeded by ``seed`` when ``shuffle``) on one domain, domain-decomposed
    (:func:`solver.parallel_nlgs.solve_problem_domains`, on ``decomposition`` when given) on
    more."""
    from . import nlgs, parallel_nlgs

    if domains > 1:
        return parallel_nlgs.solve_problem_domains(problem, x, *state, domains=domains, decomposition=decomposition,
                                                   **limits._asdict())
    return nlgs.solve_problem(problem, *state, shuffle=shuffle, seed=seed, **limits._asdict())


def solve_stepper_anderson(problem, state: ContactState, limits: Limits, *, memory=3, period=1, domains=1, x=None,
                           decomposition=None) -> NLGSResult:
    """The stepper's problem by Anderson-accelerated NLGS sweeps
    (:func:`solver.acceleration.solve_problem_anderson`): ``memory`` past sweeps combined every
    ``period`` sweeps, on ``domains`` domains."""
    from . import acceleration

    return acceleration.solve_problem_anderson(problem, *state, memory=memory, period=period, domains=domains, x=x,
                                               decomposition=decomposition, **limits._asdict())


def solve_newton(W, q, mu, tolerance, max_iterations, initial) -> ContactSolution:
    """Semi-smooth Newton (:func:`solver.nonsmooth_newton.solve`)."""
    from . import nonsmooth_newton

    return nonsmooth_newton.solve(W, q, mu, tolerance, max_iterations, initial)


def solve_pcg(W, q, mu, tolerance, max_iterations, initial) -> ContactSolution:
    """Projected conjugate gradient (:func:`solver.projected_cg.solve`)."""
    from . import projected_cg

    return projected_cg.solve(W, q, mu, tolerance, max_iterations, initial)


def solve_stepper_pcg(problem, state: ContactState, limits: Limits) -> NLGSResult:
    """The stepper's problem by projected conjugate gradient (:func:`solver.projected_cg.solve`)
    on its matrix form (:mod:`solver.matrix_form`), from the warm-start impulses, until the
    local-law residual is within ``limits.tolerance`` or ``limits.max_iterations`` iterations;
    ``state`` updated in place (the impulses, and the velocities V_free + M^-1 H^T r). The
    result's two norms are both the local-law residual |F|/|r|."""
    from . import matrix_form, projected_cg
    from .nlgs import NLGSResult

    pn, pt, vx, vy, w = state
    if pn.size == 0:
        return NLGSResult(0, 0.0, 0.0)
    H, minv = matrix_form.local_map(problem), matrix_form.inverse_mass(problem)
    W, q, mu = matrix_form.matrix_problem(problem, vx, vy, w, H, minv)
    solution = projected_cg.solve(W, q, mu, float(limits.tolerance), int(limits.max_iterations),
                                  np.stack([pn, pt], -1))
    pn[:], pt[:] = solution.impulse[:, 0], solution.impulse[:, 1]
    matrix_form.body_velocities(H, minv, solution.impulse, vx, vy, w)
    return NLGSResult(int(solution.iterations), float(solution.local_law_residual),
                      float(solution.local_law_residual))


LOCAL_LAW_NORMS = "its local-law residual |F|/|r| met the tolerance (both of its norms are that residual)"
"""What the tolerance of a method stopped by the local-law residual applies to (pcg, newton)."""


def _own_stall_words(module: str, count: str, unit: str) -> Callable[[], str]:
    """The words of a method's own stall test (:attr:`Method.own_stall`), read when called from
    its module's ``STALL_IMPROVEMENT`` and its count named ``count`` (of ``unit``), so that the
    registry imports the module only when the words are needed."""

    def words() -> str:
        solver_module = importlib.import_module(f"{__package__}.{module}")
        return (f"its own stall test (the best local-law residual down by < "
                f"{100 * solver_module.STALL_IMPROVEMENT:g}% over {getattr(solver_module, count)} {unit})")

    return words


register(Method("nlgs", "nonlinear Gauss-Seidel sweeps (serial, shuffled or on domains)", "alternative",
                solve=solve_stepper_nlgs, solve_matrix=solve_nlgs, parameters=(), domains=True, shuffle=True,
                couples_cell=True))
register(Method("anderson", "Anderson-accelerated NLGS sweeps, the same local-law residual in less time per step "
                "than 'nlgs'", "default", solve=solve_stepper_anderson,
                parameters=(("anderson_memory", "memory"), ("anderson_period", "period")), domains=True,
                couples_cell=True))
register(Method("newton", "semi-smooth Newton on Alart-Curnier's function", "experimental", solve_matrix=solve_newton,
                stall=False, label="Newton", iteration="Newton step", norms=LOCAL_LAW_NORMS,
                own_stall=_own_stall_words("nonsmooth_newton", "STALL_STEPS", "Newton steps")))
register(Method("pcg", "projected conjugate gradient (Renouf & Alart) on the step's matrix", "experimental",
                solve=solve_stepper_pcg, solve_matrix=solve_pcg, stall=False, label="Projected-CG", iteration="iteration", norms=LOCAL_LAW_NORMS,
                own_stall=_own_stall_words("projected_cg", "STALL_ITERATIONS", "iterations")))
