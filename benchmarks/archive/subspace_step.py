"""Can a Krylov step converge what the sweeps drift along?  A subspace probe on slow shear steps.

    python -m benchmarks.archive.subspace_step --sample benchmarks/_data/time_to_strain/sample_pentagon_14400_fast.pkl

The slow steps of a large sheared packing are a network-wide drift of the impulses along nearly
self-stressed paths: load moves among the contacts while the bodies hardly move
(``sweep_bursts.py``; benchmarks/archive/solver-log.md, "What the slow steps are"). Gauss–Seidel converges such
smooth, global modes slowly, and a Krylov method converges them in far fewer iterations *if*
the linear problem that holds once every contact's status is known is well posed. The probe
asks whether it is, on captured steps (:func:`sweep_bursts.capture`):

1. From the step's warm start, ``--sweeps`` plain NLGS sweeps fix the **face**: open points
   (p_n = 0), sliding points (|p_t| = mu p_n; sign s of p_t) and sticking points (the rest).
2. With De Saxcé's shift c_k = mu_k |u_t,k| frozen at that iterate, the step's problem is the
   minimisation over the Coulomb cones of

       E(p) = 1/2 p . W p + p . (q + b),     b_k = (bias_k + c_k, 0),

   W the Delassus operator (W p: the relative velocities that the impulses p alone give the
   bodies), q the relative velocities of the free motion (driven walls included), bias the
   Signorini term of the step (:mod:`solver.nlgs`). On the face, without its inequalities, p =
   P z is linear in the free unknowns z (p_n and p_t of a sticking point, p_n of a sliding one
   with p_t = s mu p_n), and E is a quadratic in z: P^T W P z = -P^T (q + b). A preconditioned
   conjugate gradient (the 2x2 or 1x1 diagonal blocks of P^T W P) starts from the sweeps'
   iterate.
3. At CG iterations 5, 10, 20 and 40: E, the norm of the reduced gradient P^T (W p + q + b),
   the points with p_n < 0 and the sticking points outside their cone, the change ‖p - p_0‖ /
   ‖p_0‖ from the sweeps' iterate p_0, and the local-law residual (:mod:`solver.residuals`)
   after projecting p onto the cones (the sweeps' own residual for comparison).
4. The direction d = p - p_0 after the last iteration: ‖W d‖ / ‖D d‖, D the points' own 2x2
   blocks W_kk (near 0 for a self-stress: impulses that move no body, which the NLGS barely
   sees), 1/2 d . W d, and the linear term d . (W p_0 + q + b) split into the parts of the
   velocities the sweeps' impulses give (W p_0), of the free velocities q, of the bias and of the
   shift. Along d, E(p_0 + s d) - E(p_0) = s d . (W p_0 + q + b) + s^2/2 d . W d: a negative
   linear term along a near-self-stress puts the face's minimum far out, and the step's solution
   is then set by the inequalities (p_n >= 0, the cones), not by the quadratic.

Writes benchmarks/archive/subspace-step-<N>.md.
"""
import argparse
import os
import time

import numpy as np

from benchmarks.common import load_sample, markdown_table, write_results
from benchmarks.shear import capture
from benchmarks.archive.sweep_bursts import _cone_projections, _relative_velocity, _velocities

HERE = os.path.dirname(os.path.abspath(__file__))
CHECKPOINTS = (5, 10, 20, 40)
"""CG iterations after which the iterate is examined."""


def delassus_apply(problem, pn, pt):
    """W p: the normal and tangential relative velocities (m s-1) that the impulses ``pn, pt``
    (N s) alone give the bodies (the free velocities left out)."""
    rest = tuple(np.zeros(problem.iinv.size) for _ in range(3))
    return _relative_velocity(problem, *_velocities(problem, rest, pn, pt))


class Face:
    """The open, sliding and sticking points of impulses ``pn, pt`` and the map p = P z.

    z has the layout of (pn, pt): its normal part is p_n of every closed point, its tangential
    part p_t of every sticking point (zero elsewhere)."""

    def __init__(self, mu, pn, pt):
        self.mu = mu
        self.closed = pn > 0.0
        self.slide = self.closed & (np.abs(pt) >= mu * pn * (1.0 - 1e-9))
        self.stick = self.closed & ~self.slide
        self.sign = np.sign(pt)

    def lift(self, zn, zt):
        """p = P z."""
        return (np.where(self.closed, zn, 0.0),
                np.where(self.stick, zt, np.where(self.slide, self.sign * self.mu * zn, 0.0)))

    def restrict(self, gn, gt):
        """P^T g."""
        return (np.where(self.slide, gn + self.sign * self.mu * gt, np.where(self.closed, gn, 0.0)),
                np.where(self.stick, gt, 0.0))

    def block_inverse(self, wnn, wnt, wtt):
        """The inverse of P^T W P's diagonal blocks, as a function of (rn, rt)."""
        slide_block = wnn + 2.0 * self.sign * self.mu * wnt + self.mu ** 2 * wtt
        det = wnn * wtt - wnt * wnt

        def apply(rn, rt):
            zn = np.where(self.stick, (wtt * rn - wnt * rt) / det, np.where(self.slide, rn / slide_block, 0.0))
            return zn, np.where(self.stick, (wnn * rt - wnt * rn) / det, 0.0)

        return apply


def probe(case: dict, n_particles: int, sweeps: int = 20, checkpoints=CHECKPOINTS) -> dict:
    """Items 1-4 of the module docstring on one captured step (``case`` from
    :func:`sweep_bursts.capture`; ``sweeps`` may be 0: the face of the warm start): a row per
    checkpoint, the direction's split, the face, the impulses before and after the CG (``start``,
    ``end``) and the frozen shift."""
    from solver import nlgs, residuals
    from solver.solve_records import Impulses, Velocities

    P = case["problem"]
    free = (case["vx"], case["vy"], case["w"])
    pn, pt = case["pn"].copy(), case["pt"].copy()
    vx, vy, w = _velocities(P, free, pn, pt)
    blocks = nlgs.delassus(P)
    wnn, wnt, wtt = blocks
    order = np.arange(P.a.size)
    for _ in range(sweeps):
        nlgs.sweep(order, P, Impulses(pn, pt), Velocities(vx, vy, w), blocks)
    face = Face(P.mu, pn, pt)
    un, ut = _relative_velocity(P, vx, vy, w)
    qn, qt = _relative_velocity(P, *free)
    shift = P.mu * np.abs(ut)
    bn = P.bias + shift

    def energy(n, t):
        wn, wt = delassus_apply(P, n, t)
        return 0.5 * np.sum(n * wn + t * wt) + np.sum(n * (qn + bn) + t * qt)

    precondition = face.block_inverse(wnn, wnt, wtt)
    xn, xt = np.where(face.closed, pn, 0.0), np.where(face.stick, pt, 0.0)  # z of p_0: P z = p_0
    rn, rt = face.restrict(-(un + bn), -ut)
    zn, zt = precondition(rn, rt)
    dn, dt = zn.copy(), zt.copy()
    rz = np.sum(rn * zn + rt * zt)
    scale = np.sqrt(np.sum(pn ** 2 + pt ** 2))
    rows = [dict(iterations=0, energy=energy(pn, pt), gradient=float(np.sqrt(np.sum(rn ** 2 + rt ** 2))),
                 negative=0, outside=0, change=0.0, law=residuals.local_law_residual(P, pn, pt, vx, vy, w))]
    for it in range(1, max(checkpoints) + 1):
        if rz > 0.0:  # else the face's quadratic is solved exactly: the iterate stays
            an, at = face.restrict(*delassus_apply(P, *face.lift(dn, dt)))
            alpha = rz / np.sum(dn * an + dt * at)
            xn, xt = xn + alpha * dn, xt + alpha * dt
            rn, rt = rn - alpha * an, rt - alpha * at
            zn, zt = precondition(rn, rt)
            rz, previous = np.sum(rn * zn + rt * zt), rz
            dn, dt = zn + rz / previous * dn, zt + rz / previous * dt
        if it in checkpoints:
            new_n, new_t = face.lift(xn, xt)
            cone_n, cone_t = _cone_projections(new_n, new_t, P.mu)
            rows.append(dict(
                iterations=it, energy=energy(new_n, new_t), gradient=float(np.sqrt(np.sum(rn ** 2 + rt ** 2))),
                negative=int(np.sum(new_n[face.closed] < 0.0)),
                outside=int(np.sum(np.abs(new_t[face.stick]) > P.mu[face.stick] * new_n[face.stick])),
                change=float(np.sqrt(np.sum((new_n - pn) ** 2 + (new_t - pt) ** 2)) / scale),
                law=residuals.local_law_residual(P, cone_n, cone_t, *_velocities(P, free, cone_n, cone_t))))
    d_n, d_t = new_n - pn, new_t - pt
    wn, wt = delassus_apply(P, d_n, d_t)
    own = np.hypot(wnn * d_n + wnt * d_t, wnt * d_n + wtt * d_t)
    walls = (P.a >= n_particles) | (P.b >= n_particles)
    return dict(step=case.get("step"), sweeps_default=case.get("sweeps"), points=P.a.size, face=face,
                start=(pn, pt), end=(new_n, new_t), shift=shift,
                closed=int(face.closed.sum()), sliding=int(face.slide.sum()), rows=rows,
                self_stress=float(np.sqrt(np.sum(wn ** 2 + wt ** 2)) / np.sqrt(np.sum(own ** 2))),
                quadratic=float(0.5 * np.sum(d_n * wn + d_t * wt)),
                linear_free=float(np.sum(d_n * qn + d_t * qt)), linear_bias=float(np.sum(d_n * P.bias)),
                linear_shift=float(np.sum(d_n * shift)), linear_iterate=float(np.sum(d_n * (un - qn) + d_t * (ut - qt))),
                wall_share=float(np.sum((d_n ** 2 + d_t ** 2)[walls]) / np.sum(d_n ** 2 + d_t ** 2)))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sample", required=True, help="a pickled compacted sample (compaction.py --save)")
    parser.add_argument("--steps", type=int, nargs=2, default=(10, 30), metavar=("A", "B"),
                        help="the shear steps captured (default 10 30)")
    parser.add_argument("--burst", type=int, default=200, help="sweeps that make a step a burst step (default 200)")
    parser.add_argument("--sweeps", type=int, default=20, help="plain sweeps that fix the face (default 20)")
    parser.add_argument("--out", help="the results file (default benchmarks/archive/subspace-step-<N>.md)")
    args = parser.parse_args(argv)
    sim, _ = load_sample(args.sample)
    n = sim.n_particles
    start = time.perf_counter()
    caught = capture(sim, *args.steps)
    sweeps = [c["sweeps"] for c in caught]
    print(f"captured steps {args.steps[0]}-{args.steps[1]} in {time.perf_counter() - start:.0f} s: sweeps {sweeps}",
          flush=True)
    cases = [("burst", c) for c in caught if c["sweeps"] >= args.burst][:2]
    cases += [("quiet", c) for c in caught if c["sweeps"] < min(60, args.burst)][:1]
    rows, directions = [], []
    for kind, case in cases:
        r = probe(case, n, args.sweeps)
        for row in r["rows"]:
            rows.append([r["step"], kind, r["sweeps_default"], row["iterations"], f"{row['energy']:.4e}",
                         f"{row['gradient']:.2e}", row["negative"], row["outside"], f"{row['change']:.3f}",
                         f"{row['law']:.2e}"])
            print(rows[-1], flush=True)
        directions.append([r["step"], kind, r["points"], r["closed"], r["sliding"], f"{r['self_stress']:.4f}",
                           f"{r['quadratic']:+.4f}", f"{r['linear_free']:+.4f}", f"{r['linear_bias']:+.4f}",
                           f"{r['linear_shift']:+.4f}", f"{r['linear_iterate']:+.4f}", f"{r['wall_share']:.3f}"])
        print(directions[-1], flush=True)
    path_table = markdown_table(
        ["step", "kind", "default: sweeps", "CG iterations", "E (J)", "reduced gradient (m s-1)", "closed points with p_n < 0",
         "sticking points outside their cone", "‖p - p_0‖ / ‖p_0‖", "local-law residual, projected"], rows)
    direction_table = markdown_table(
        ["step", "kind", "points", "closed", "sliding", "‖W d‖ / ‖D d‖", "1/2 d.W d (J)", "d.q: free velocities",
         "d.bias", "d.shift", "d.W p_0", "walls' share of ‖d‖²"], directions)
    out = args.out or os.path.join(HERE, f"subspace-step-{n}.md")
    intro = (f"Written by `python -m benchmarks.archive.subspace_step --sample {os.path.relpath(args.sample, os.path.dirname(os.path.dirname(HERE)))} "
             f"--steps {args.steps[0]} {args.steps[1]}`: {n} particles, shear steps {args.steps[0]}-{args.steps[1]} "
             f"(sweeps per step with the default solve: {sweeps}), the face fixed by {args.sweeps} plain sweeps. "
             "The script's docstring defines each column; benchmarks/archive/solver-log.md (\"What the slow steps are\") reads them.")
    write_results(out, "A Krylov step on the face the sweeps find", intro,
                  ["## The conjugate gradient on the face (row 0: the sweeps' iterate)", path_table,
                   "## The direction it takes: d = p - p_0 after the last iteration", direction_table])


if __name__ == "__main__":
    main()
