"""What a run or a study says before it starts: its expected wall time, stage by stage
(:func:`grainview.app.paper_size.study_estimate`), and the kernels compiled first, on a cold
cache, with their progress."""

from __future__ import annotations

import sys

from .progress import SampleProgress


def print_estimate(preps, tests, parameters, jobs, shares=None, report=True, load=None):
    """Print the expected wall time of the study: each stage of each sample on idle cores, with
    where its cost comes from, the compiling (``shares``: :func:`grainview.app.warmup.cold_shares`
    of a cold cache) and the report (``report``), the machine's load (``load``: (load average,
    cores), default this machine's) and what it makes of them, and the whole
    (:func:`grainview.app.paper_size.study_estimate`)."""
    from grainview.app.paper_size import STUDY_TIME, hours, machine_load, study_estimate
    from solver.engine import Parameters

    p = Parameters(**parameters)
    load, cores = machine_load() if load is None else load
    shares = {group: share for group, (share, _) in (shares or {}).items() if share}
    whole = study_estimate({label: (prep, tests[label]) for label, prep in preps.items()}, p.time_step,
                           domains=p.domains, jobs=jobs, compile_share=shares, report=report, load=load, cores=cores)
    for label, stages in whole["samples"].items():
        for stage, (steps, cost, seconds, source) in stages.items():
            print(f"estimate: {label} ({preps[label].particles}), {stage}: ~{steps} steps x {cost:.3g} us per particle "
                  f"and step = ~{hours(seconds)} ({source})", flush=True)
    idle, factor, seconds = whole["idle"], whole["factor"], whole["seconds"]
    extra = []
    if idle["compile"]:
        which = " and ".join(f"{100 * share:.0f}% of the {group}'s" for group, share in shares.items())
        extra.append(f"compiling {which} kernels (not in numba's cache for this processor) ~{hours(idle['compile'])}")
    if report:
        extra.append(f"the report ~{hours(idle['report'])}")
    if extra:
        print(f"estimate: {', '.join(extra)}, on an idle core ({STUDY_TIME})", flush=True)
    if factor["simulation"] > 1 or factor["compile"] > 1:
        busy = "busy" if max(factor.values()) >= 1.5 else "lightly loaded"
        print(f"estimate: this machine is {busy} (load {load:.1f} on {cores} cores): each stage takes longer than on "
              f"idle cores, ~{factor['simulation']:.1f}x for the {whole['processes']} simulating process(es), "
              f"~{factor['compile']:.1f}x for one process (compiling, the report)", flush=True)
    else:
        print(f"estimate: the cores are free (load {load:.1f} on {cores} cores): the times above hold as they are",
              flush=True)
    parts = [f"{name} ~{hours(seconds[key])}" for key, name in
             (("compile", "compiling"), ("simulation", "the samples"), ("report", "the report")) if seconds[key]]
    print(f"estimate: the study ~{hours(whole['total'])} of wall time ({', '.join(parts)}; "
          f"{'side by side' if jobs > 1 else 'one after the other'}, "
          f"{'serial sweeps' if p.domains <= 1 else f'{p.domains} domains'}), within a factor of about 2; a "
          "stopped or killed run resumes with the same command", flush=True)


def compile_line(command, shares, load) -> str:
    """The line that says, before anything else, that the kernels are compiled first and for
    about how long (``shares``: :func:`grainview.app.warmup.cold_shares`; ``load``: (load
    average, cores)); "" on a warm cache."""
    from grainview.app.paper_size import COMPILE_SECONDS, hours, load_factor

    seconds = sum(COMPILE_SECONDS[group] * share for group, (share, _) in shares.items())
    if not seconds:
        return ""
    seconds *= load_factor(1, *load)
    return (f"{command}: compiling the kernels, first run only, about {hours(seconds)} (grainview warmup does it ahead "
            "of time)")


def compile_ahead(command, shares, progress):
    """Compile, in this process and before any work, the kernels that ``shares``
    (:func:`grainview.app.warmup.cold_shares`) names, with progress: a line per stage of the
    warm-up's workload (:func:`grainview.app.warmup.warm_up`) with the kernels compiled so far,
    and in a terminal a bar over the kernels (``progress``: the command line's flag, None:
    auto), else a line a minute too. Ends with a line saying how long it took."""
    from time import monotonic

    from grainview.app.paper_size import hours

    from .warmup import GROUPS, warm_up

    names = {name for _, found in shares.values() for name in found}
    if not names:
        return
    packages = tuple(package for group in GROUPS for package in GROUPS[group]
                     if group in shares and (group != "analysis" or shares[group][0]))
    done, start = set(), monotonic()
    bar = None
    if (sys.stderr.isatty() if progress is None else progress is True):
        from tqdm.std import tqdm

        bar = tqdm(total=len(names), desc=f"{command}: compiling", unit="kernel", leave=False)

    last = [start]

    def compiled(name):
        if name in names and name not in done:
            done.add(name)
            if bar is not None:
                bar.update(1)
            elif monotonic() - last[0] >= SampleProgress.every:  # a log's line now and then
                last[0] = monotonic()
                print(f"{command}: compiling: {len(done)} of {len(names)} kernels, {hours(last[0] - start)}",
                      flush=True)

    def log(line):
        last[0] = monotonic()
        text = (f"{command}: compiling, stage {line}; {len(done)} of {len(names)} kernels so far, "
                f"{hours(last[0] - start)}")
        if bar is not None:
            bar.write(text)
        else:
            print(text, flush=True)

    from solver.engine import sigterm_raises

    try:
        with sigterm_raises():  # nothing is written yet: SIGTERM stops the command at once, as Ctrl-C does
            result = warm_up(log=log, packages=packages, compiled=compiled)
    finally:
        if bar is not None:
            bar.close()
    print(f"{command}: kernels compiled in {hours(monotonic() - start)} ({len(done)} compiled, the others loaded; "
          f"cache: {result['cache']})", flush=True)
