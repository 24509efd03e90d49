"""A test too long for one sitting, carried from machine to machine in the repository.

The paper-size tests at 1 cm/s take a day of one core (docs/fidelity.md, section 4); a sitting
lasts hours and the next may start on a fresh machine, with nothing of the last but the
repository. A run's file is too large to commit (megabytes a snapshot). What a run needs to go
on is small: its first snapshot (the test's start: eps_q is measured from it) and its last
(the whole solver state with its warm start, :mod:`solver.restart`); what its page needs of the
snapshots in between is smaller still: each snapshot's descriptors
(:func:`benchmarks.fidelity.measure.snapshot_measures`, both counting conventions). So::

    # at the end of a sitting, the run stopped (Ctrl-C, or its process killed):
    python -m benchmarks.fidelity.carry save RUNS benchmarks/fidelity/carry/paper_size_1cm
    git add benchmarks/fidelity/carry/paper_size_1cm && git commit ...

    # the next sitting, on any machine, from a clone of the repository:
    python -m benchmarks.fidelity.carry restore benchmarks/fidelity/carry/paper_size_1cm RUNS
    python -m benchmarks.fidelity.reshear benchmarks/fidelity/samples RUNS --velocity 0.01 ...  # resumes

``save`` measures the snapshots of ``RUNS/<label>.nc`` not measured yet, adds them to
``CARRY/<label>.measures.nc`` and writes ``CARRY/<label>.nc``: the run's first and last
snapshots, compressed (:func:`grainview.contract.writer.copy_snapshots`). ``restore`` copies
that file into ``RUNS``; the reshear's own resume then goes on from its last snapshot, bit for
bit as if never stopped (tests/benchmarks/test_carry.py checks it), and the next ``save`` adds
the new snapshots' measures. ``python -m benchmarks.fidelity.paper_size CARRY`` reads the
measures where a folder has no run file. The folder's README.md says where each run stands.
"""

from __future__ import annotations

import argparse
import os
import sys

import numpy as np

from grainview.contract.errors import ParameterError

COUNTINGS = ("force-bearing", "near")
"""The counting conventions measured: the contacts that carry a force, and with them the pairs
within :data:`benchmarks.fidelity.RELATION_NEAR` of d_min (the relations' second column)."""


def _near_gaps() -> dict:
    from benchmarks.fidelity.__main__ import D_MIN, RELATION_NEAR

    return dict(zip(COUNTINGS, (None, RELATION_NEAR * D_MIN)))


def measures_path(folder, label) -> str:
    return os.path.join(os.fspath(folder), f"{label}.measures.nc")


def load_measures(folder, label, counting="force-bearing"):
    """The carried measures of ``label`` in ``folder`` in one counting convention
    (:data:`COUNTINGS`), as :func:`benchmarks.fidelity.measure.snapshot_measures` returns them;
    None when there are none."""
    import xarray as xr

    path = measures_path(folder, label)
    if not os.path.exists(path):
        return None
    with xr.open_dataset(path) as ds:
        both = ds.load()
    one = both.sel(counting=counting)
    near = float(one["near_m"])
    one = one.drop_vars(["counting", "near_m"])
    one.attrs["near_m"] = near
    return one


def _measure(path, known_steps):
    """Both countings' measures of the snapshots of ``path`` whose step is not in ``known_steps``
    (dim counting first)."""
    import xarray as xr

    from benchmarks.fidelity.measure import snapshot_measures

    parts = []
    gaps = _near_gaps()
    for near in gaps.values():
        m = snapshot_measures(path, near)
        parts.append(m.isel(time=np.flatnonzero(~np.isin(m["step"].values, known_steps))))
    both = xr.concat(parts, dim="counting", data_vars="all", coords="minimal", compat="override",
                     combine_attrs="drop_conflicts")
    return both.assign_coords(counting=list(gaps), near_m=("counting", [-1.0 if g is None else g for g in gaps.values()]))


def save(run_path, carry, label=None) -> dict:
    """Carry the (stopped) run ``run_path`` into the folder ``carry``: its new snapshots'
    measures added to ``<label>.measures.nc``, its first and last snapshots written to
    ``<label>.nc`` (``label``: the file's name without .nc). Returns where the run stands:
    ``{"step", "eps_q", "snapshots measured", "new"}``. Refuses a run of other settings than the
    carried one, and a run that does not start where the carried one started."""
    import xarray as xr

    from grainview.contract.writer import copy_snapshots
    from solver.restart import check_settings

    run_path = os.fspath(run_path)
    label = label or os.path.splitext(os.path.basename(run_path))[0]
    os.makedirs(carry, exist_ok=True)
    state_file = os.path.join(os.fspath(carry), f"{label}.nc")
    path = measures_path(carry, label)
    old = None
    if os.path.exists(path):
        with xr.open_dataset(path) as ds:
            old = ds.load()
    if os.path.exists(state_file):
        with xr.open_dataset(state_file) as ds:
            settings = {k: ds.attrs[k] for k in ("wall_velocity_m_s", "snapshot_every", "strain_target", "n_particles")
                        if k in ds.attrs}
            first_step = int(ds["step"].values[0])
        try:
            check_settings(run_path, settings, "carry it into another folder")
        except FileExistsError as exc:
            raise ParameterError(str(exc)) from None
        with xr.open_dataset(run_path) as ds:
            if int(ds["step"].values[0]) != first_step:
                raise ParameterError(f"{run_path} starts at step {int(ds['step'].values[0])}, the run carried in "
                                     f"{carry} at {first_step}: not the same test; carry it into another folder")
    known = old["step"].isel(counting=0).values if old is not None else np.array([], dtype=np.int64)
    new = _measure(run_path, known)
    measures = new if old is None else xr.concat([old, new], dim="time", combine_attrs="override")
    steps = measures["step"].isel(counting=0).values
    measures = measures.isel(time=np.argsort(steps, kind="stable"))
    measures.attrs["eps_q_max"] = float(measures["eps_q"].max())
    temporary = path + ".part"
    measures.to_netcdf(temporary, encoding={name: {"zlib": True, "complevel": 4} for name in measures.data_vars})
    copy_snapshots(run_path, state_file, [0, -1])  # the state after the measures: a kill between them re-measures
    os.replace(temporary, path)
    return {"step": int(steps.max()), "eps_q": float(measures["eps_q"].isel(counting=0).values[-1]),
            "snapshots measured": int(measures.sizes["time"]), "new": int(new.sizes["time"])}


def restore(carry, runs, label) -> str:
    """Copy the carried run ``carry/<label>.nc`` into the folder ``runs`` so that the reshear
    resumes it; refuses to replace a run file there. Returns the path written."""
    import shutil

    source = os.path.join(os.fspath(carry), f"{label}.nc")
    if not os.path.exists(source):
        raise ParameterError(f"{source}: no such carried run (expected the file `save` writes)")
    os.makedirs(runs, exist_ok=True)
    target = os.path.join(os.fspath(runs), f"{label}.nc")
    if os.path.exists(target):
        raise ParameterError(f"{target} exists: resume it as it is, or move it away to restore the carried run")
    shutil.copyfile(source, target + ".part")
    os.replace(target + ".part", target)
    return target


def status(carry) -> list[str]:
    """Where each test carried in the folder ``carry`` stands, one line each: the steps done of
    the test's, the last eps_q and the snapshots measured (what its README quotes)."""
    import netCDF4

    lines = []
    for name in sorted(os.listdir(carry)):
        if not name.endswith(".measures.nc"):
            continue
        label = name[: -len(".measures.nc")]
        m = load_measures(carry, label)
        with netCDF4.Dataset(os.path.join(os.fspath(carry), f"{label}.nc")) as nc:
            total = int(nc.getncattr("biaxial_steps"))
        steps = m["step"].values
        done = int(steps[-1] - steps[0])
        lines.append(f"{label}: step {done:,} of {total:,} ({100 * done / total:.1f}%), eps_q {float(m['eps_q'][-1]):.3f}, "
                     f"{m.sizes['time']} snapshots measured")
    return lines


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.fidelity.carry", description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="action", required=True)
    s = sub.add_parser("save", help="carry the stopped runs of RUNS into CARRY")
    s.add_argument("runs", help="the runs' folder (<label>.nc)")
    s.add_argument("carry", help="the folder kept in the repository")
    r = sub.add_parser("restore", help="copy the carried runs of CARRY into RUNS, to be resumed")
    r.add_argument("carry")
    r.add_argument("runs")
    for p in (s, r):
        p.add_argument("--labels", nargs="+", default=["pentagons", "disks"], help="the runs (default: both)")
    t = sub.add_parser("status", help="where each test carried in CARRY stands")
    t.add_argument("carry")
    args = parser.parse_args(argv)
    try:
        if args.action == "status":
            print("\n".join(status(args.carry)))
            return 0
        for label in args.labels:
            if args.action == "save":
                run = os.path.join(args.runs, f"{label}.nc")
                if not os.path.exists(run):
                    continue
                where = save(run, args.carry, label)
                print(f"{label}: step {where['step']}, eps_q {where['eps_q']:.4f}, {where['snapshots measured']} "
                      f"snapshots measured ({where['new']} new); carried in {args.carry}")
            elif os.path.exists(os.path.join(args.carry, f"{label}.nc")):
                print(f"{label}: {restore(args.carry, args.runs, label)} (resume it with the reshear's command)")
    except (ParameterError, OSError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
