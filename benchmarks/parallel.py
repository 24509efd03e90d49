"""Both cores: the domain-decomposed NLGS (``Parameters(domains=D)``, solver/parallel_nlgs.py)
against the serial sweep on dense sheared samples.

    python -m benchmarks.parallel            # writes benchmarks/results/parallel.md
    python -m benchmarks.parallel --quick    # small sizes, checks the script (_data/)

Each case starts from one dense state — the compacted 4000-pentagon and 4000-disk samples at the
start of their tests (built by ``python -m benchmarks.samples --build --sizes 4000``), and, where
the fidelity study's 4000-pentagon test is cached (``python -m benchmarks.fidelity --large``),
a snapshot of its residual state — and runs
the same biaxial steps once with the serial NLGS and once with D domains on D numba threads, in
fresh processes, one after the other. Reported: sweeps per step (median and 90th percentile),
solve time and whole-step time per particle per step, the speed-up of each, and the local-law
(natural-map) residual, so that a speed-up comes with the accuracy it was bought at, and the
cores left idle by other processes just before each measurement: a thread pool shares the cores with whatever else
runs, so a number measured beside another busy process is not this solver's speed.
"""

from __future__ import annotations

import os

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))

from benchmarks.common import capture_contact_problems, in_fresh_process, machine_description, markdown_table

RUNS = os.path.join(HERE, "_data", "fidelity", "runs")
SAMPLES = os.path.join(HERE, "_data", "fidelity", "samples")


def _measure(path, index, domains, steps, velocity):
    import time
    import warnings
    from dataclasses import replace

    import numba

    from solver import load_sample

    warnings.simplefilter("ignore")
    numba.set_num_threads(max(1, domains))
    sim = load_sample(path, index)
    sim.parameters = replace(sim.parameters, domains=domains)
    sim.walls.drive_velocity("top", (0.0, -velocity))
    sim.step()  # compile outside the timing
    for key in sim.timings:
        sim.timings[key] = 0.0
    sweeps, law = [], []
    start = time.perf_counter()
    for _ in range(steps):
        info = sim.step()
        sweeps.append(info.iterations)
        law.append(info.local_law_residual)
    total = time.perf_counter() - start
    return {"sweeps": np.array(sweeps), "law": np.array(law), "total": total, "solve": sim.timings["solve"],
            "particles": sim.n_particles, "threads": numba.get_num_threads()}


def _one_sweep(path, repeats):
    """Time one sweep on one fixed contact problem (the first biaxial step of ``path``'s last
    snapshot): the serial NLGS sweep, and the domain sweep with 1 and 2 threads, each repeated
    ``repeats`` times on the same arrays — the cost per sweep without the trajectories parting."""
    import time
    import warnings
    import numba

    from solver import load_sample, nlgs, parallel_nlgs
    from solver.solve_records import DelassusBlocks, Impulses, Velocities

    warnings.simplefilter("ignore")
    sim = load_sample(path, -1)
    sim.walls.drive_velocity("top", (0.0, -0.032))
    problem, *state, _ = capture_contact_problems(sim)[0]
    blocks = nlgs.delassus(problem)

    def timed(call):
        call()
        start = time.perf_counter()
        for _ in range(repeats):
            call()
        return (time.perf_counter() - start) / repeats

    serial_impulses = Impulses(*(a.copy() for a in state[:2]))
    serial_velocities = Velocities(*(a.copy() for a in state[2:]))
    order = np.arange(problem.a.size)
    out = {"serial": timed(lambda: nlgs.sweep(order, problem, serial_impulses, serial_velocities, blocks)),
           "points": problem.a.size}
    dec = parallel_nlgs.decompose(problem, sim.position[:sim.n_particles, 0], 2)
    renumbered, new_impulses, new_velocities = dec.gather(problem, *[a.copy() for a in state])
    new_blocks = DelassusBlocks(*(x[dec.point_order] for x in blocks))
    out["interface"] = dec.interface.size
    for threads in (1, 2):
        numba.set_num_threads(threads)
        out[threads] = timed(lambda: parallel_nlgs.sweep_domains(dec.ptr, dec.points, dec.interface, renumbered,
                                                                 new_impulses, new_velocities, new_blocks))
    return out


def one_sweep_table(chosen, repeats=300):
    rows = []
    for label, path, index, velocity, steps in chosen:
        if index != -1:
            continue
        idle = idle_cores()
        r, _ = in_fresh_process(_one_sweep, path, repeats)
        rows.append([label, r["points"], f"{r['interface']} ({r['interface'] / r['points']:.1%})",
                     f"{r['serial'] * 1e6:.0f}", f"{r[1] * 1e6:.0f}", f"{r[2] * 1e6:.0f}",
                     f"{r['serial'] / r[2]:.2f}", f"{idle:.2f}"])
        print(rows[-1], flush=True)
    return markdown_table(["sample", "contact points", "interface points", "serial sweep (µs)",
                           "2 domains, 1 thread (µs)", "2 domains, 2 threads (µs)", "speed-up per sweep",
                           "idle cores before"], rows)


def cases(quick):
    """(label, file, snapshot, top-wall speed m/s, steps) of each measured state; the dense
    compacted samples of benchmarks/samples.py, and the residual state of the fidelity study's
    4000-pentagon test where that run is cached."""
    if quick:
        return [("pentagons, 1000, compacted (start of the test)", os.path.join(SAMPLES, "pentagon_1000_paper_s0.nc"),
                 -1, 0.016, 20)]
    chosen = [("pentagons, 4000, compacted (start of the test)", os.path.join(SAMPLES, "pentagon_4000_paper_s0.nc"),
               -1, 0.032, 300),
              ("disks, 4000, compacted (start of the test)", os.path.join(SAMPLES, "disk_4000_paper_s0.nc"), -1,
               0.032, 300)]
    residual = os.path.join(RUNS, "pentagon_4000_paper_s0_v3.2cm_e0.2.nc")
    if os.path.exists(residual):
        chosen.insert(1, ("pentagons, 4000, residual state (eps_q ~ 0.45)", residual, 70, 0.032, 300))
    return chosen


def larger_samples():
    """The cached 14,400-particle samples (benchmarks/samples.py), for the one-sweep table only:
    300 steps of them would take an hour."""
    found = []
    for shape, label in (("pentagon", "pentagons"), ("disk", "disks")):
        path = os.path.join(SAMPLES, f"{shape}_14400_paper_s0.nc")
        if os.path.exists(path):
            found.append((f"{label}, 14,400, compacted (start of the test)", path, -1, 0.06, 0))
    return found


def check_samples(chosen):
    """Refuse, naming the command that builds them, when the samples are not cached."""
    missing = [path for _, path, *_ in chosen if not os.path.exists(path)]
    if missing:
        sizes = "1000" if all("_1000_" in p for p in missing) else "4000"
        raise SystemExit(f"parallel.py: missing dense sample(s) {', '.join(os.path.basename(p) for p in missing)}; "
                         f"build them with: python -m benchmarks.samples --build --sizes {sizes} --jobs 2")


def idle_cores(seconds=2.0):
    """Cores left idle by every other process over the next ``seconds`` (from /proc/stat); nan
    where /proc/stat cannot be read."""
    import time

    def sample():
        with open("/proc/stat") as fh:
            values = [float(v) for v in fh.readline().split()[1:]]
        return values[3] + values[4], sum(values)  # idle + iowait, total

    try:
        idle0, total0 = sample()
        time.sleep(seconds)
        idle1, total1 = sample()
    except OSError:
        return float("nan")
    return (idle1 - idle0) / (total1 - total0) * (os.cpu_count() or 1)


def run(chosen, domains=2):
    """The steps table of the ``chosen`` cases (:func:`cases`, checked by :func:`check_samples`)."""
    rows = []
    for label, path, index, velocity, steps in chosen:
        load = {"serial": idle_cores()}
        serial, _ = in_fresh_process(_measure, path, index, 1, steps, velocity)
        load["parallel"] = idle_cores()
        parallel, _ = in_fresh_process(_measure, path, index, domains, steps, velocity)
        n = serial["particles"]
        for key, name, r in (("serial", "serial NLGS", serial),
                             ("parallel", f"{domains} domains, {parallel['threads']} threads", parallel)):
            rows.append([label, name, steps, f"{np.median(r['sweeps']):.0f} ({np.percentile(r['sweeps'], 90):.0f})",
                         f"{r['solve'] / steps / n * 1e6:.1f}", f"{r['total'] / steps / n * 1e6:.1f}",
                         f"{serial['solve'] / r['solve']:.2f}", f"{serial['total'] / r['total']:.2f}",
                         f"{np.median(r['law']):.2e}", f"{load[key]:.2f}"])
            print(rows[-1], flush=True)
    header = ["sample", "solver", "steps", "sweeps/step median (p90)", "solve µs/particle/step",
              "step µs/particle/step", "solve speed-up", "step speed-up", "local-law residual (median)",
              "idle cores before"]
    return markdown_table(header, rows)


def main(argv=None):
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--domains", type=int, default=2)
    parser.add_argument("--out", help="the results file (default benchmarks/results/parallel.md; with --quick benchmarks/_data/parallel-quick.md)")
    args = parser.parse_args(argv)
    output = args.out or (os.path.join(HERE, "_data", "parallel-quick.md") if args.quick else
                          os.path.join(HERE, "results", "parallel.md"))
    chosen = cases(args.quick)
    check_samples(chosen)
    sweep_text = one_sweep_table(chosen + ([] if args.quick else larger_samples()), 20 if args.quick else 300)
    text = run(chosen, args.domains)
    body = ["# Both cores: domain-decomposed NLGS", "",
            f"Generated by `python -m benchmarks.parallel{' --quick' if args.quick else ''}`; see docs/solver.md, \"Both cores\".",
            "", machine_description(), "",
            "## One sweep on one contact problem", "",
            "The first biaxial step's contact problem of each compacted sample, swept repeatedly on the same "
            "arrays (the state evolves, the problem does not): the cost of a sweep, without two solvers' "
            "trajectories parting.", "", sweep_text, "",
            f"## {300 if not args.quick else 20} biaxial steps", "",
            "The same steps run by each solver from the same state; the orders converge to different "
            "admissible solutions, so the sweep counts differ and the speed-up mixes the cost of a sweep "
            "with the number of sweeps.", "", text, ""]
    with open(output, "w") as fh:
        fh.write("\n".join(body))
    print(f"wrote {output}")


if __name__ == "__main__":
    main()
