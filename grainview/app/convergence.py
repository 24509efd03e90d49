"""How well a run's contact problems were solved, as its file records it: the steps whose NLGS
stopped before its stopping norms met their tolerances, and how far their impulses were from
satisfying the contact laws (docs/solver.md, "Solution measures").

The solver stops a step's nonlinear Gauss–Seidel iterations when two norms of the impulses'
change over a sweep fall below their tolerances (``solver_tolerance`` for the quadratic norm,
``solver_max_tolerance`` for the max norm), or, failing that, at its sweep cap
(``solver_max_iterations``) or at the stall test (``solver_stall_sweeps`` > 0: the best
quadratic norm fell by less than 5% over that many sweeps). A step stopped the second way is
*unconverged*: its forces are kept as they are. Each snapshot records how many steps since the
previous snapshot were (``nlgs_unconverged_steps``), the largest quadratic norm among them
(``nlgs_unconverged_residual``, the norm the tolerance applies to) and their largest local-law
residual |F|/|r| (``nlgs_unconverged_local_law_residual``: zero for every exact solution of
Signorini's and Coulomb's laws, whatever force network it is). The snapshots' own
``local_law_residual`` (their last step, almost always converged) gives the value those laws
are met to at the tolerance, to compare with.

Needs numpy only: it reads a netCDF4 dataset's variables or an xarray dataset alike.
"""

from __future__ import annotations

import numpy as np

from ..contract.schema import complete_snapshots

COUNT = "nlgs_unconverged_steps"
"""The variable that holds, per snapshot, the unconverged steps since the previous one."""


def _number(attrs, key):
    try:
        return float(attrs[key])
    except (KeyError, TypeError, ValueError):  # absent, or "none"
        return None


def unconverged_in_file(variables, attrs) -> dict | None:
    """The unconverged steps of a run's file, over its complete snapshots.

    Parameters
    ----------
    variables : mapping
        Variable name to array-like (a netCDF4 dataset's ``variables``, or an xarray dataset).
    attrs : mapping
        The file's global attributes (the solver's ``solver_*`` settings).

    Returns
    -------
    dict or None
        None when the file has no ``nlgs_unconverged_steps`` (written by another code, or
        before the solver recorded it). Otherwise ``steps`` (unconverged steps written),
        ``of`` (steps between the first and the last snapshot, from ``step``; None without
        it), ``snapshots`` (snapshots with at least one), ``residual`` and
        ``local_law_residual`` (the largest among them, 1; 0 when there are none),
        ``typical_local_law_residual`` (median of the snapshots' own ``local_law_residual``;
        None without it) and the solver's ``tolerance``, ``max_tolerance``, ``max_iterations``
        and ``stall_sweeps`` (None where the file does not say).
    """
    if COUNT not in variables:
        return None
    keep = complete_snapshots(variables)

    def values(name):
        return np.asarray(variables[name][:])[keep] if name in variables else None

    counts = values(COUNT).astype(np.int64)
    step = values("step")
    snapshot_law = values("local_law_residual")

    def largest(name):
        data = values(name)
        return float(np.max(data, initial=0.0)) if data is not None else float("nan")

    return {
        "steps": int(counts.sum()),
        "of": int(step[-1] - step[0]) if step is not None and step.size else None,
        "snapshots": int(np.count_nonzero(counts)),
        "residual": largest("nlgs_unconverged_residual"),
        "local_law_residual": largest("nlgs_unconverged_local_law_residual"),
        "typical_local_law_residual": (float(np.median(snapshot_law)) if snapshot_law is not None
                                       and snapshot_law.size else None),
        "tolerance": _number(attrs, "solver_tolerance"),
        "max_tolerance": _number(attrs, "solver_max_tolerance"),
        "max_iterations": _number(attrs, "solver_max_iterations"),
        "stall_sweeps": _number(attrs, "solver_stall_sweeps"),
        "solver": solver_name(attrs),
    }


def compaction_in_file(attrs) -> dict | None:
    """The compaction's unconverged steps, as a file's attributes record them.

    Parameters
    ----------
    attrs : mapping
        The file's global attributes (``compaction_steps``, ``compaction_unconverged_steps``,
        ``compaction_unconverged_local_law_residual``: :class:`solver.sample_history.SampleHistory`).

    Returns
    -------
    dict or None
        None when the file does not record them (a run not compacted by this package's
        preparation). Otherwise ``steps`` (the compaction's unconverged steps), ``of`` (its
        steps; None where the file does not say) and ``local_law_residual`` (the largest
        local-law residual |F|/|r| among them, 1; 0 when there are none).
    """
    if "compaction_unconverged_steps" not in attrs:
        return None
    of = _number(attrs, "compaction_steps")
    law = _number(attrs, "compaction_unconverged_local_law_residual")
    return {"steps": int(attrs["compaction_unconverged_steps"]), "of": None if of is None else int(of),
            "local_law_residual": float("nan") if law is None else law}


def compaction_text(compaction: dict | None) -> str:
    """One sentence, for a reader of the report, on the compaction's unconverged steps
    (:func:`compaction_in_file`), which the test's count leaves out; "" when the file does not
    record them."""
    if compaction is None:
        return ""
    of = f"its {compaction['of']} steps" if compaction["of"] is not None else "its steps"
    head = f"The isotropic compaction before the test (its steps are not counted above): {compaction['steps']} of {of}"
    if compaction["steps"] == 0:
        return f"{head} stopped unconverged."
    return (f"{head} stopped unconverged, the largest local-law residual |F|/|r| among them "
            f"{compaction['local_law_residual']:.2g} (the file's compaction_unconverged_* attributes).")


def solver_name(attrs) -> str:
    """The contact solver a file's steps were solved with: its ``solver_solver``, or for a file
    written before that attribute its ``solver_acceleration`` ("anderson" or the plain NLGS)."""
    from solver.engine import from_acceleration

    if "solver_solver" in attrs:
        return str(attrs["solver_solver"])
    try:
        return from_acceleration(str(attrs.get("solver_acceleration", "off")))
    except ValueError:  # a value no version of the solver wrote
        return "nlgs"


def _method(counts: dict):
    """The registered method of ``counts['solver']`` (default the NLGS), or None for a name this
    package does not know."""
    from solver.engine import solver_method

    try:
        return solver_method(counts.get("solver") or "nlgs")
    except ValueError:
        return None


def stop_rule(counts: dict) -> str:
    """What stopped the unconverged steps, in the words of their contact solver
    (:func:`solver.contact_solvers.stop_rule`): its iteration cap and, when it was on, its stall
    test."""
    from solver.engine import stop_rule as solver_stop_rule

    m = _method(counts)
    if m is None:
        return "the iteration cap or a stall test"
    return solver_stop_rule(m.name, counts.get("max_iterations"), counts.get("stall_sweeps"))


def norms_phrase(counts: dict) -> str:
    """What the solver's tolerances apply to, as the words after "before"."""
    m = _method(counts)
    return m.norms if m is not None else "its stopping norms met their tolerances"


def tolerances(counts: dict) -> str:
    """The stopping norms' tolerances, as a phrase."""
    parts = []
    if counts.get("tolerance") is not None:
        parts.append(f"quadratic norm {counts['tolerance']:.2g}")
    if counts.get("max_tolerance") is not None:
        parts.append(f"max norm {counts['max_tolerance']:.2g}")
    return ", ".join(parts) or "as the file does not say"


def residual_comparison(counts: dict) -> str:
    """How far the unconverged steps were from a solution: their largest quadratic norm against
    its tolerance and their largest local-law residual against the snapshots' median."""
    tol = counts.get("tolerance")
    quad = f"the largest quadratic norm among them was {counts['residual']:.2g}"
    if tol and np.isfinite(counts["residual"]):
        quad += f" ({counts['residual'] / tol:.2g}x its tolerance)"
    law = (f"the largest local-law residual |F|/|r| {counts['local_law_residual']:.2g} (zero for an exact "
           "solution of the contact laws")
    typical = counts.get("typical_local_law_residual")
    law += f"; the snapshots' own steps: median {typical:.2g})" if typical is not None else ")"
    return f"{quad}, {law}"


def unconverged_text(counts: dict | None, what: str = "the test") -> str:
    """One paragraph, for a reader of the report, on the unconverged steps of a file
    (:func:`unconverged_in_file`); ``what`` names the steps the file covers."""
    if counts is None:
        return ("NLGS convergence: not recorded in this file (no nlgs_unconverged_steps: written by another code "
                "or an older solver).")
    of = f" of {what}'s {counts['of']}" if counts["of"] is not None else f" of {what}"
    m = _method(counts)
    heading = f"{m.label if m is not None else 'Contact-solver'} convergence"
    if counts["steps"] == 0:
        return f"{heading}: every step{of} stopped once {norms_phrase(counts)} ({tolerances(counts)})."
    share = f" ({100 * counts['steps'] / counts['of']:.2g}%)" if counts["of"] else ""
    return (f"{heading}: {counts['steps']}{of} steps{share}, in {counts['snapshots']} of the intervals "
            f"between snapshots, stopped at {stop_rule(counts)} before {norms_phrase(counts)} "
            f"({tolerances(counts)}); their forces are kept as they are. "
            f"{residual_comparison(counts)[0].upper()}{residual_comparison(counts)[1:]}. Recorded per snapshot in "
            f"the file's {COUNT} (docs/schema.md).")
