"""The ``grainview`` command line: ``study``, ``run``, ``report``, ``info`` and ``demo``.

Errors a user can cause are printed as one line (``grainview: error: ...``) with exit code 2,
never as a traceback.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .errors import GrainviewError


def _info(args) -> int:
    from .io import open_dataset
    from .validation import validate

    ds = open_dataset(args.file)
    print(f"{args.file}: {ds.sizes.get('time', 0)} snapshots, {ds.sizes['particle']} particles, "
          f"{ds.sizes.get('wall', 0)} walls, {ds.sizes['contact']} contact slots")
    n_vertices = ds["n_vertices"].values
    shapes = {int(k): int((n_vertices == k).sum()) for k in sorted(set(n_vertices.tolist()))}
    print("shapes: " + ", ".join(f"{c} {'disks' if k == 0 else f'{k}-gons'}" for k, c in shapes.items()))
    if ds.sizes.get("time", 0):
        t = ds["time"].values
        print(f"time: {t[0]:g} .. {t[-1]:g} s; contacts per snapshot: "
              f"{int(ds['contact_count'].min())} .. {int(ds['contact_count'].max())}")
    for key, value in ds.attrs.items():
        print(f"  {key} = {value}")
    validate(ds, source=str(args.file))
    print("valid: follows grainview data contract " + str(ds.attrs.get("grainview_schema_version", "?")))
    return 0


def _demo(args) -> int:
    from . import open_dataset
    from .schema import netcdf_encoding
    from .synthetic import harmonic_series

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    path = out / "synthetic.nc"
    if path.exists() and not args.overwrite:
        raise GrainviewError(f"{path} exists; pass --overwrite to replace it")
    ds = harmonic_series(n_snapshots=args.snapshots, n_contacts=args.contacts, seed=args.seed)
    tmp = path.with_suffix(".nc.part")
    ds.to_netcdf(tmp, encoding=netcdf_encoding(ds))
    tmp.replace(path)
    lazy = open_dataset(path, chunks=5, validate=True)
    table = lazy.grain.harmonic_prediction().compute()
    table["a"] = lazy.grain.fabric_anisotropy()["a"].compute()
    frame = table.to_dataframe()[["q_over_p", "prediction", "a_prime", "a_n", "a_t"]]
    print(f"wrote {path}; q/p against the harmonic prediction (a' + a_n + a_t)/2:")
    print(frame.round(4).to_string())
    frame.to_csv(out / "harmonic_prediction.csv")
    return 0


def _simulate(shape, particles, strain, every, path, seed, overwrite, progress, scene="biaxial"):
    """Deposit, compact isotropically and (for ``scene="biaxial"``) shear one sample into
    ``path``; returns the path. An isotropic run writes its final compacted state."""
    import warnings

    from solver import biaxial_test, compaction_sample, isotropic_compaction
    from solver.output import Recorder

    path = Path(path)
    if path.exists() and not overwrite:
        raise GrainviewError(f"{path} exists; pass --overwrite to replace it")
    print(f"{shape}: depositing {particles} particles and compacting under 10 kPa ...", flush=True)
    sim = compaction_sample(particles, shape, seed=seed)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        steps = isotropic_compaction(sim, progress=progress)
        settled = "settled" if sim.settled else "NOT settled (step limit reached)"
        print(f"{shape}: compaction {settled} after {steps} steps; wall stresses "
              f"{', '.join(f'{s:.0f}' for s in sim.compaction_stress)} Pa", flush=True)
        if scene == "isotropic":
            with Recorder(path, sim, attrs={"scene": "isotropic", "sigma0_Pa": sim.sigma0}, overwrite=overwrite) as rec:
                rec.write()
        else:
            print(f"{shape}: biaxial compression to eps_1 = {strain} ...", flush=True)
            biaxial_test(sim, path, strain=strain, every=every, overwrite=overwrite, progress=progress)
    unconverged = sum("did not converge" in str(w.message) for w in caught)
    if unconverged:
        print(f"{shape}: warning: NLGS reached its iteration limit in {unconverged} step(s)", file=sys.stderr)
    print(f"{shape}: wrote {path}", flush=True)
    return path


def _progress_flag(args):
    return None if args.progress == "auto" else args.progress == "on"


def _run(args) -> int:
    _simulate(args.shape, args.particles, args.strain, args.every, args.out, args.seed, args.overwrite,
              _progress_flag(args), scene=args.scene)
    return 0


def _report(args) -> int:
    from .io import open_dataset
    from .report import write_report

    labels = args.labels.split(",") if args.labels else [Path(f).stem for f in args.files]
    if len(labels) != len(args.files):
        raise GrainviewError(f"--labels has {len(labels)} names for {len(args.files)} files")
    runs = {label: open_dataset(f, validate=True) for label, f in zip(labels, args.files)}
    result = write_report(runs, args.out, overwrite=args.overwrite)
    print(result["table"].to_string())
    print(f"wrote {len(result['files'])} files in {args.out}")
    return 0


def _study(args) -> int:
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    paths = {}
    for label, shape in (("pentagons", "pentagon"), ("disks", "disk")):
        paths[label] = _simulate(shape, args.particles, args.strain, args.every, out / f"{label}.nc", args.seed,
                                 args.overwrite, _progress_flag(args))
    args.files = [str(p) for p in paths.values()]
    args.labels = ",".join(paths)
    args.out = str(out / "report")
    return _report(args)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="grainview", description=(
        "Contact dynamics of disks and polygons, and the force-transmission analyses of "
        "Azema et al., Phys. Rev. E 76, 011301 (2007)."))
    sub = parser.add_subparsers(dest="command", required=True)

    def simulation_options(p, particles=400, strain=0.05, every=100):
        p.add_argument("--particles", type=int, default=particles, help=f"particles per sample (default {particles})")
        p.add_argument("--strain", type=float, default=strain,
                       help=f"vertical strain eps_1 of the biaxial test (default {strain})")
        p.add_argument("--every", type=int, default=every, help=f"steps between snapshots (default {every})")
        p.add_argument("--seed", type=int, default=0, help="random seed of the deposit (default 0)")
        p.add_argument("--overwrite", action="store_true", help="replace existing output files")
        p.add_argument("--progress", choices=["auto", "on", "off"], default="auto",
                       help="progress bars (default: on in a terminal)")

    study = sub.add_parser("study", help="the paper's study: pentagons vs disks, simulated, analysed, plotted",
                           description="Deposit, compact (10 kPa) and shear an S1-like pentagon sample and an "
                           "S2-like disk sample, then write the report (table vs the paper, figures).")
    study.add_argument("--out", default="study", help="output folder (default: study)")
    simulation_options(study)
    study.set_defaults(func=_study)

    run = sub.add_parser("run", help="simulate one sample into a netCDF file",
                         description="Geometric deposit, isotropic compaction under sigma_0 = 10 kPa, then "
                         "(scene biaxial) compression at 1 cm/s with sigma_0 held laterally.")
    run.add_argument("scene", nargs="?", choices=["biaxial", "isotropic"], default="biaxial",
                     help="biaxial (default) or isotropic (writes the compacted state)")
    run.add_argument("--shape", default="pentagon", help="pentagon (default), disk, or a number of vertices")
    run.add_argument("--out", default="run.nc", help="output netCDF file (default: run.nc)")
    simulation_options(run)
    run.set_defaults(func=_run)

    report = sub.add_parser("report", help="analyse runs: headline table vs the paper and all figures")
    report.add_argument("files", nargs="+", help="netCDF files of the grainview contract")
    report.add_argument("--labels", default=None, help="comma-separated labels (default: file names); "
                        "labels containing 'pent' or 'disk' are compared with the paper's S1/S2 values")
    report.add_argument("--out", default="report", help="output folder (default: report)")
    report.add_argument("--overwrite", action="store_true", help="replace an existing report in --out")
    report.set_defaults(func=_report)
    info = sub.add_parser("info", help="validate a grainview netCDF file and print its summary")
    info.add_argument("file", help="path of a netCDF file of the grainview data contract")
    info.set_defaults(func=_info)
    demo = sub.add_parser("demo", help="write a synthetic harmonic-model series and analyse it lazily")
    demo.add_argument("--out", default="demo-out", help="output folder (default: demo-out)")
    demo.add_argument("--snapshots", type=int, default=11, help="number of snapshots (default 11)")
    demo.add_argument("--contacts", type=int, default=20000, help="contacts per snapshot (default 20000)")
    demo.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    demo.add_argument("--overwrite", action="store_true", help="replace existing output files")
    demo.set_defaults(func=_demo)
    return parser


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return args.func(args)
    except (GrainviewError, FileExistsError, FileNotFoundError) as exc:
        message = str(exc).replace("\n", "\n  ")
        print(f"grainview: error: {message}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("grainview: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
