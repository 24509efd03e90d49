"""Shear a study's compacted samples again at another top-wall speed, without compacting them again.

The paper-size study (``grainview study --paper-size``) spends a large part of its pentagons'
time in the compaction (docs/fidelity.md, section 4: 1.5 h of their 3.4 h). To shear its
samples at another speed, or again on another machine, this script takes the compacted sample
of each file of ``source`` -- the first snapshot of a finished study's test, the state the test
started from, or the one snapshot of a compacted sample (``grainview study --scene isotropic``),
with its warm start (:func:`solver.load_sample`) -- and shears it to ``--strain`` (default:
the original test's, or the biaxial test's default for a compacted sample) at ``--velocity``.
The repository keeps the paper-size samples (:data:`PAPER_SAMPLES`), so on a fresh clone::

    python -m benchmarks.fidelity.reshear benchmarks/fidelity/samples paper_size_1cm \
        --velocity 0.01 --every 1200 --domains 1 --samples pentagons

``--every`` keeps the snapshots at the same strain spacing as the original file when it is
scaled with the speed (200 steps at 6 cm/s -> 1200 at 1 cm/s). ``--domains`` sets the sweeps'
domains for the new test (the compaction's stay what they were; the file records both).

**It resumes**: the same command again skips a finished file and carries on a partial one from
its last snapshot (:func:`solver.restart.resume`, bit for bit); ``python -m solver.restart FILE``
does the same for one file. The output files are those of the study's (the data contract,
with near pairs), so ``python -m benchmarks.fidelity.paper_size OUT --reference STUDY400`` and
``grainview report`` read them. Nothing in the source folder is written.
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from contextlib import contextmanager
from pathlib import Path

from grainview.contract.errors import ParameterError

SAMPLES = ("pentagons", "disks")

PAPER_SAMPLES = Path("benchmarks/fidelity/samples")
"""Where the repository keeps the paper-size study's compacted samples (14,400 pentagons, 10,000
disks), from the repository's root; ``samples/README.md`` there says how they were made."""


def reshear(source: Path, out: Path, label: str, *, velocity: float, every: int, domains: int | None,
            strain: float | None = None, wall_mass: float | None = None, progress: bool = False) -> str:
    """Shear the compacted sample of ``source/label.nc`` into ``out/label.nc`` (or resume it).

    Returns what was done: "finished" (skipped), "resumed" or "started". An existing
    ``out/label.nc`` of another ``velocity``, ``every``, ``strain`` or ``wall_mass`` (the right
    wall's mass in units of the sample's, :class:`solver.parameters.BiaxialTest`; None: the
    compaction's) is refused (ParameterError, one line) rather than resumed or kept as if it
    were the test asked for.
    """
    from solver import load_sample
    from solver.restart import check_settings, file_state, resume
    from solver.scenes import biaxial_test

    path = out / f"{label}.nc"
    state = file_state(path)
    if state in ("finished", "partial"):  # only a test of the speed and snapshots asked for is kept or resumed
        expected = {"wall_velocity_m_s": velocity, "snapshot_every": every, "right_wall_mass_ratio": wall_mass}
        if strain is not None:
            expected["strain_target"] = strain
        try:
            check_settings(path, expected, "give another out folder, or the settings it was started with")
        except FileExistsError as exc:
            raise ParameterError(str(exc)) from None
    if state == "finished":
        resume(path, compress=True)  # compresses a file whose compression was stopped; else nothing
        return "finished"
    if state == "partial":
        with one_line_on_unconverged(path):
            resume(path, progress=progress)
        return "resumed"
    original = source / f"{label}.nc"
    from grainview.app.study import compacted_state
    from grainview.contract.reader import ContractFile
    from solver.engine import BiaxialTest

    settings = {}
    if original.exists():
        with ContractFile(original) as ds:
            settings = dict(ds.attrs)
    compacted = settings.get("scene") == "isotropic"
    if (compacted_state(original) if compacted else file_state(original)) != "finished":
        raise ParameterError(f"{original} is neither a finished test nor a compacted sample; expected a study's "
                             "complete file (grainview study, scene biaxial or isotropic)")
    sim = load_sample(original, 0)
    if domains is not None:
        sim.set_parameters(domains=domains)
    attrs = {"resheared_from": str(original)}
    if compacted:
        target = BiaxialTest.strain if strain is None else strain
    else:
        target = float(settings["strain_target"]) if strain is None else strain
        attrs["resheared_from_velocity_m_s"] = float(settings["wall_velocity_m_s"])
    out.mkdir(parents=True, exist_ok=True)
    with one_line_on_unconverged(path):
        biaxial_test(sim, path, strain=target, velocity=velocity, every=every, wall_mass=wall_mass,
                     near_contacts=True, attrs=attrs, progress=progress)
    return "started"


@contextmanager
def one_line_on_unconverged(path, taken="the steps taken now"):
    """The steps whose contact solver stopped at its cap, said in one line at the end (or when
    stopped) from the file's records, as ``grainview study`` does, instead of a warning each;
    other warnings shown as they come."""
    from grainview.app.simulation import reissue, resumed_unconverged_warning
    from grainview.contract.errors import ConvergenceWarning

    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            yield
    finally:  # outside the recording: the warnings shown again are not recorded again
        reissue(caught)
        unconverged = sum(issubclass(w.category, ConvergenceWarning) for w in caught)
        if unconverged and path.exists():
            print(f"{path.stem}: warning: {resumed_unconverged_warning(path, unconverged, taken)}", file=sys.stderr)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.fidelity.reshear", description=__doc__.split("\n")[0])
    parser.add_argument("source", type=Path, help="folder of a finished study or of its compacted samples "
                        "(pentagons.nc, disks.nc; grainview study --scene isotropic), e.g. " + str(PAPER_SAMPLES))
    parser.add_argument("out", type=Path, help="folder for the new tests (created)")
    parser.add_argument("--velocity", type=float, required=True, help="top-wall speed of the new tests (m/s)")
    parser.add_argument("--every", type=int, required=True, help="steps between snapshots")
    parser.add_argument("--domains", type=int, default=None, help="domains of the new tests' sweeps")
    parser.add_argument("--strain", type=float, default=None, help="eps_1 to reach (default: the original's)")
    parser.add_argument("--wall-mass", type=float, default=None,
                        help="the right wall's mass in units of the sample's (default: the compaction's, the sample's)")
    parser.add_argument("--samples", default=",".join(SAMPLES), help="which samples, comma-separated")
    parser.add_argument("--progress", action="store_true", help="show a progress bar")
    args = parser.parse_args(argv)
    labels = [s for s in args.samples.split(",") if s]
    unknown = sorted(set(labels) - set(SAMPLES))
    if unknown:
        parser.error(f"--samples: {unknown} unknown; expected some of {', '.join(SAMPLES)}")
    if args.source.resolve() == args.out.resolve():
        parser.error("out is the source folder; expected another folder (the study's files are only read)")
    for label in labels:
        start = time.monotonic()
        print(f"{label}: ...", flush=True)
        try:
            done = reshear(args.source, args.out, label, velocity=args.velocity, every=args.every,
                           domains=args.domains, strain=args.strain, wall_mass=args.wall_mass,
                           progress=args.progress)
        except ParameterError as exc:
            print(f"reshear: error: {exc}", file=sys.stderr)
            return 2
        except KeyboardInterrupt:  # Ctrl-C: the solver has said where the test stopped and how to go on
            return 130
        print(f"{label}: {done} ({(time.monotonic() - start) / 3600:.2f} h of wall time)", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
