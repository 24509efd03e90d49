"""Where the impulse changes of NLGS sweeps are, in dense sheared packings: could a sweep skip the
points (or regions) that have stopped changing?

    python -m benchmarks.archive.sweep_changes pentagon      # 1000 particles, preset fast, 300 biaxial steps

Compacts 1000 particles (preparation 'fast'), shears them 300 steps (top wall 1 cm/s), captures
the contact problems of the next 20 steps and re-solves every fourth one sweep by sweep, printing
after sweeps 1, 5, 20, 50 and the last: the quadratic norm, the share of points carrying 99% and
99.9% of the sum of dV_k^2 = dp_k . W_k dp_k over the sweep, and the share of points whose
impulse changed at all. Results are quoted in benchmarks/archive/solver-log.md ("Skipping converged points").
"""
import sys
import warnings
import numpy as np
from benchmarks.common import capture_contact_problems
from solver import nlgs
from solver.preparation import preparation, prepare_sample
from solver.solve_records import Impulses, Velocities


def main():
    warnings.simplefilter("ignore")
    shape = sys.argv[1]
    prep = preparation("fast", shape=shape, particles=1000)
    sim = prepare_sample(prep, progress=False)
    sim.walls.drive_velocity("top", (0.0, -0.01))
    for _ in range(300):
        sim.step()
    problems = capture_contact_problems(sim, 20)
    for P, pn, pt, vx, vy, w, opt in problems[:20:4]:
        m = P.a.size
        blocks = nlgs.delassus(P)
        wnn, wnt, wtt = blocks
        impulses, velocities = Impulses(pn, pt), Velocities(vx, vy, w)
        nlgs.velocities_from_impulses(P, impulses, velocities)
        order = np.arange(m)
        rows = []
        for it in range(1, 2001):
            pn0, pt0 = pn.copy(), pt.copy()
            s, mx, _, _ = nlgs.sweep(order, P, impulses, velocities, blocks)
            q, worst = nlgs.norms(s, mx, impulses, blocks)
            dpn, dpt = pn - pn0, pt - pt0
            dv2 = dpn * (wnn * dpn + wnt * dpt) + dpt * (wnt * dpn + wtt * dpt)
            if it in (1, 5, 20, 50) or (q <= opt["tolerance"] and worst <= opt["max_tolerance"]):
                srt = np.sort(dv2)[::-1]; c = np.cumsum(srt) / max(srt.sum(), 1e-300)
                f99 = (np.searchsorted(c, 0.99) + 1) / m; f999 = (np.searchsorted(c, 0.999) + 1) / m
                rows.append(f"sweep {it}: quad {q:.2e}; points carrying 99% of the change {f99:.3f}, 99.9% {f999:.3f}; points changed at all {np.mean(dv2 > 0):.3f}")
            if q <= opt["tolerance"] and worst <= opt["max_tolerance"]:
                break
        print(f"step: {m} points, converged after {it} sweeps")
        for r in rows: print("   ", r)
        sys.stdout.flush()


if __name__ == "__main__":
    main()
