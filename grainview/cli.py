"""The ``grainview`` command line: ``info FILE`` and ``demo``.

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


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="grainview", description=(
        "Contact dynamics of disks and polygons, and the force-transmission analyses of "
        "Azema et al., Phys. Rev. E 76, 011301 (2007)."))
    sub = parser.add_subparsers(dest="command", required=True)
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
    except (GrainviewError, FileExistsError) as exc:
        message = str(exc).replace("\n", "\n  ")
        print(f"grainview: error: {message}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("grainview: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
