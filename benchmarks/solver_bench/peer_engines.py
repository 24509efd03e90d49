"""Section c: this solver against pymunk and Box2D on the same settled pile (benchmarks/peers.py
runs the peers in their own environment)."""

from __future__ import annotations

import os
import subprocess
import warnings

import numpy as np

from benchmarks.common import in_fresh_process, markdown_table

from .config import Config, DATA, HERE, PEER_PYTHON
from .helpers import fmt, largest_overlap, reset_meters, run_steps


def settle_pile(n, shape, steps, seed=0):
    """Deposit ``n`` particles (paper size mix) between side walls and settle them under
    gravity with this solver, 50 steps at a time for at most ``steps`` steps, until the pile is
    at rest (kinetic energy below 10^-6 m g d) and free of overlaps: the overlap recovery did
    not run in the last 50 steps (no end-of-step overlap above its threshold). A pile still
    being pushed apart at the recovery's speed cap is not settled, and every engine would spend
    its timed steps on that.

    Returns
    -------
    dict
        The pile in the format benchmarks/peers.py reads, and the settling's record:
        ``kinetic_energy`` (J), ``largest_overlap`` (over the last 50 steps, in smallest
        diameters), ``settle_steps`` and ``settled`` (False when ``steps`` ran out first).
    """
    from solver import gravity_scene
    from solver.packing import box_width_for, deposit
    from solver.shapes import n_vertices_of

    if steps < 50:
        raise ValueError(f"settle_pile: steps={steps}: expected at least 50 (the pile is checked every 50 steps)")
    width = box_width_for(n, aspect_ratio=1.0)
    pos, ang, rad, nv, height = deposit(n, nvert=n_vertices_of(shape), width=width, seed=seed)
    sim = gravity_scene(pos, ang, rad, nv, sides=(0.0, width))
    weight_scale = float(sim.mass.sum()) * 9.81 * 2 * float(rad.mean())  # J
    p = sim.parameters
    done, settled = 0, False
    while done < steps and not settled:
        recovery_sweeps = sim.counters["recovery_sweeps"]
        _, _, overlap, _ = run_steps(sim, 50)
        done += 50
        settled = (sim.kinetic_energy() < 1e-6 * weight_scale
                   and sim.counters["recovery_sweeps"] == recovery_sweeps)
    return dict(position=sim.position.copy(), angle=sim.angle.copy(), radius=rad, n_vertices=nv.astype(np.int64),
                first_vertex=sim.shapes.first_vertex, local_vertices=sim.shapes.local_vertices(),
                density=p.density, box=np.array([0.0, 0.0, width, height]), gravity=np.array(p.gravity),
                dt=p.time_step, friction=p.friction, kinetic_energy=sim.kinetic_energy(),
                largest_overlap=overlap / (2 * float(rad.min())), settle_steps=done, settled=settled)


def save_pile(pile, path):
    """Write a :func:`settle_pile` pile to ``path`` (.npz) in the format benchmarks/peers.py
    reads (without the settling's own record)."""
    np.savez(path, **{k: v for k, v in pile.items() if k not in ("kinetic_energy", "largest_overlap", "settle_steps", "settled")})


def _ours_on_pile(path, steps, iterations, tolerance, measured):
    """This solver on the pile: ``iterations`` sweeps every step (``tolerance`` None), or until
    ``tolerance`` (the quadratic norm; the max norm in the defaults' ratio; "default": the
    defaults) with at most 2000 sweeps; then ``measured`` untimed steps whose floor force over
    the weight is recorded, one value per step.

    Returns
    -------
    dict
        ``per_step`` (s, timed steps), ``floor`` (array of the measured steps' floor force over
        the weight), ``sweeps`` and ``recovery_sweeps`` per timed step, ``parts`` (ms per timed
        step of each stage), ``ns`` (solve time per point-sweep), ``points``, ``pairs``,
        ``unconverged`` (steps, timed and measured, that did not reach the tolerance; 0 at a
        fixed budget), and the final ``position`` and ``angle``.
    """
    from solver import Parameters, gravity_scene

    pile = dict(np.load(path))
    x0, _, x1, _ = pile["box"]
    defaults = Parameters()
    if tolerance is None:
        kwargs = dict(max_iterations=iterations, tolerance=1e-30, max_tolerance=1e-30)
    elif tolerance == "default":
        kwargs = {}
    else:
        kwargs = dict(tolerance=tolerance, max_tolerance=tolerance * defaults.max_tolerance / defaults.tolerance)
    sim = gravity_scene(pile["position"], pile["angle"], pile["radius"], pile["n_vertices"], sides=(x0, x1),
                        gravity=float(-pile["gravity"][1]), time_step=float(pile["dt"]), **kwargs)
    run_steps(sim, 2)  # numba caches loaded
    reset_meters(sim)
    elapsed, bad, _, _ = run_steps(sim, steps)
    # the timed steps' meters, before the measured steps add to them
    sweeps = sim.counters["sweeps"] / steps
    recovery_sweeps = sim.counters["recovery_sweeps"] / steps
    parts = {k: 1e3 * v / steps for k, v in sim.timings.items()}
    ns = 1e9 * sim.timings["solve"] / max(sim.counters["point_sweeps"], 1)
    floor = []
    with warnings.catch_warnings():  # a fixed budget stops every step at its cap, by design
        warnings.simplefilter("ignore")
        for _ in range(measured):
            bad += not sim.step().converged
            floor.append(-sim.wall_forces()[0, 1])
    ratio = np.array(floor) / (sim.mass.sum() * abs(pile["gravity"][1]))
    return dict(position=sim.position, angle=sim.angle, per_step=elapsed / steps, floor=ratio, sweeps=sweeps, parts=parts,
                recovery_sweeps=recovery_sweeps, ns=ns, points=sim.last.n_points, pairs=sim.points.n_pairs,
                unconverged=0 if tolerance is None else bad)


def floor_errors(ratio):
    """(|mean - 1|, per-step RMS of ratio - 1) of the floor force over the weight, one ``ratio``
    per step. In a pile at rest the floor carries the weight in every step; over many steps the
    mean tends to the weight whatever the solver does (the pile's momentum stays near zero), so
    the per-step RMS is the measure of how well each step's forces balance the weight."""
    error = np.asarray(ratio, dtype=float) - 1.0
    return abs(float(error.mean())), float(np.sqrt(np.mean(error ** 2)))


def section_peers(cfg: Config, log=print):
    from solver import Walls

    os.makedirs(DATA, exist_ok=True)
    have_peers = os.path.exists(PEER_PYTHON)
    rows, settled_note = [], []
    for shape in ("pentagon", "disk"):
        pile = settle_pile(cfg.peer_particles, shape, cfg.peer_settle_steps)
        path = os.path.join(DATA, f"pile_{shape}_{cfg.peer_particles}.npz")
        save_pile(pile, path)
        n = len(pile["radius"])
        diameter = 2 * float(pile["radius"].mean())
        x0, _, x1, _ = pile["box"]
        walls = Walls.floor(sides=(x0, x1))
        note = (f"{shape} pile: {pile['settle_steps']} steps, E_kin {pile['kinetic_energy']:.2g} J, largest overlap "
                f"{pile['largest_overlap']:.1e} of the smallest diameter over its last 50 steps"
                + ("" if pile["settled"] else f", NOT settled within {cfg.peer_settle_steps} steps"))
        log(note)
        settled_note.append(note)
        cases = [("this solver", b, None) for b in cfg.peer_budgets] + [("this solver (default tol.)", None, "default")]
        cases += [("this solver", None, t) for t in cfg.peer_tolerances]
        cases += [(e, b, None) for e in ("pymunk", "box2d") for b in cfg.peer_budgets]
        for engine, budget, tolerance in cases:
            try:
                if engine.startswith("this solver"):
                    r, _ = in_fresh_process(_ours_on_pile, path, cfg.peer_steps, budget or 2000, tolerance,
                                            cfg.peer_measured_steps)
                    q = r["parts"]
                    extra = (f"{r['sweeps']:.0f} sweeps/step, {r['ns']:.0f} ns/point/sweep, "
                             f"{r['points']} points / {r['pairs']} pairs; ms/step: NLGS {q['solve']:.2f}, "
                             f"update with overlap recovery {q['update']:.2f} ({r['recovery_sweeps']:.2f} recovery sweeps), detection {q['broad_phase'] + q['narrow_phase']:.2f}"
                             + (f"; {r['unconverged']} of {cfg.peer_steps + cfg.peer_measured_steps} steps stopped by the "
                                "2000-sweep cap" if r["unconverged"] else ""))
                    budget_text = (f"{budget} sweeps" if tolerance is None else "tol. 1.7e-4 (<= 2000)"
                                   if tolerance == "default" else f"tol. {tolerance:g} (<= 2000)")
                else:
                    if not have_peers:
                        rows.append([shape, engine, f"{budget}", "-", "-", "-", "-", "-", "peer venv missing"])
                        continue
                    out = os.path.join(DATA, f"peer_{engine}_{shape}_{budget}.npz")
                    subprocess.run([PEER_PYTHON, os.path.join(HERE, "peers.py"), path, out, "--engine", engine,
                                    "--steps", str(cfg.peer_steps), "--iterations", str(budget),
                                    "--measured", str(cfg.peer_measured_steps)], check=True,
                                   capture_output=True, text=True, timeout=900)
                    res = dict(np.load(out))
                    r = dict(position=res["position"], angle=res["angle"], per_step=float(res["time_per_step"]),
                             floor=res["floor_over_weight"])
                    extra = ("velocity = position iterations" if engine == "box2d" else "") + "; fixed budget"
                    budget_text = f"{budget} iterations"
                overlap = largest_overlap(r["position"], r["angle"], pile["radius"], pile["n_vertices"], walls.point,
                                          walls.normal)
                rows.append([shape, engine, budget_text, f"{1e3 * r['per_step']:.2f}", f"{1e6 * r['per_step'] / n:.1f}",
                             *(fmt(e) for e in floor_errors(r["floor"])), fmt(overlap / diameter), extra])
            except Exception as exc:  # a peer failing must not stop the run
                rows.append([shape, engine, f"{budget}", "-", "-", "-", "-", "-", f"failed: {str(exc)[:100]}"])
            log(rows[-1])
    header = ["pile", "engine", "budget", "ms / step", "us / step / particle",
              f"|floor force / weight - 1|, mean of {cfg.peer_measured_steps} steps",
              "floor force / weight - 1, per-step RMS",
              "largest overlap / mean d", "notes"]
    text = (f"Piles of {cfg.peer_particles} particles (paper size mix, box width for h/l ~ 1, side walls, friction "
            f"0.4 between grains, 0 with walls) deposited geometrically and settled by this solver for "
            f"up to {cfg.peer_settle_steps} steps (until E_kin < 1e-6 m g d and the overlap recovery, which runs when "
            f"an end-of-step overlap exceeds 1e-4 of the smallest diameter, ran in none of the last 50 steps; "
            f"{'; '.join(settled_note)}), saved to .npz and reloaded into every engine in a fresh process "
            f"(PEERS.md). Each engine then runs {cfg.peer_steps} timed steps at dt = 5e-4 s with the stated "
            f"budget; then the floor force is recorded in each of {cfg.peer_measured_steps} further steps (not "
            f"timed), and its error against the weight given as the mean's and per step (RMS): over many steps "
            f"the mean tends to the weight whatever the solver does (the pile's momentum stays near zero), so the "
            f"per-step RMS is the accuracy measure; overlap "
            f"measured on each engine's final positions with this project's narrow phase (same metric for all). "
            f"This solver at a fixed budget: tolerance 1e-30 so it always spends max_iterations sweeps; its "
            f"overlap-recovery pass keeps its own settings (tolerance 1e-2, at most 50 sweeps, run only where an "
            f"overlap exceeds 1e-4 d: a loosely solved step makes overlaps, and the pass then runs; its sweeps and "
            f"the update stage's time, which includes it, are in the notes, all per timed step). This solver to a "
            f"tolerance: the default one, and tighter ones with the max norm in the defaults' ratio (at most 2000 "
            f"sweeps), the NLGS sweeps as the defaults say (Anderson-accelerated). Box2D "
            f"runs in units of 2.5 cm; pymunk collision_slop 1e-5 m (benchmarks/peers.py).\n\n")
    if not have_peers:
        text += (f"**Peer engines not run**: {PEER_PYTHON} not found; create it with `python3 -m venv /tmp/peervenv && "
                 "/tmp/peervenv/bin/pip install -r benchmarks/requirements-peers.txt`.\n\n")
    return text + markdown_table(header, rows), rows
