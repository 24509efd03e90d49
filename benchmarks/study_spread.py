"""The study's numbers that docs/analysis.md quotes, measured on several 400-particle runs of each
shape: the value in each run, and over the runs the range, mean and standard deviation.

A 400-particle run is one chaotic trajectory, so one run's numbers are not the shapes' numbers;
docs/analysis.md quotes ranges over runs ("Force chains", "Coarse-grained fields", "Topology of
the force network"). This script computes them, with the same code as the notebooks that draw
them, so that the numbers can be regenerated:

* notebooks/coarse_graining.ipynb: its table (residual state, the nodes two widths inside the
  box), the band finder's rows (the residual window and its two halves), the local q/p spread at
  four kernel widths, the grid integrals against the Love-Weber stress and the mass (every
  snapshot);
* notebooks/force_chains.ipynb: its summary (residual state) and its lifetimes table (every
  snapshot, chains followed), with what docs/analysis.md adds: the snapshots' standard deviation
  of the chain count and of the shares, the pooled share of chains of 3 and of 20 or more
  particles, the sample's major stress direction, the strain span of the longest life;
* notebooks/network_topology.ipynb: its table (residual state, particle-particle contacts), with
  beta_0 at xi = 0.5, the loops at xi = 0 per snapshot, the share of them left at xi = 1, and the
  4-cliques of the force-bearing particle-particle network in every snapshot of the run;
* the weak network of the same residual states (docs/analysis.md, "Force chains"): its share of
  the contacts (``contact_proportions``, the report's weak fraction) and q(1)/p (``xi_profile``),
  the fabric anisotropy a, and a'(xi) at xi = 0.05 and 0.1 ("Near contacts").

The runs: ``grainview study --seed K --out DIR`` (defaults: 400 pentagons and 400 disks, each a
``pentagons.nc`` and a ``disks.nc``); docs/analysis.md's tables use seeds 0-3 made by the current
solver and a seed-0 study made by the code before commit 2875063 (which made the solver
processor-independent and so changed the trajectories; the current code cannot remake that one):
five runs per shape, the runs of docs/reproducibility.md, "Tolerances from measured scatter".

Usage::

    python -m benchmarks.study_spread measure --run seed0=STUDY0 --run seed1=STUDY1 ... --out spread.json
    python -m benchmarks.study_spread summary spread.json

``measure`` reads one file at a time, lazily, and writes the JSON after each (a file already in
it is skipped, so an interrupted measurement resumes); it took 10-20 s per file on two shared cores.
``summary`` prints, per quantity and shape, each run's value, the range, the mean and the
standard deviation (n - 1), and the value of the run named ``seed0`` (``--current``), as
docs/analysis.md's tables give them: "range (current seed 0)".
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time

import numpy as np

SHAPES = ("pentagons", "disks")


# --- notebooks/coarse_graining.ipynb ----------------------------------------------------------

def coarse_graining(ds) -> dict:
    """The notebook's exactness, table, band and width cells (cells 6, 10, 15 and 19)."""
    import xarray as xr

    from grainview.analysis import sample
    from grainview.analysis.coarse_graining import field_invariants, interior, mean_diameter, scalar_field
    from grainview.analysis.shear_bands import find_shear_band

    fields = ds.grain.coarse_grained()
    dx, dy = fields.attrs["spacing_m"]
    love_weber = ds.grain.stress_tensor() * sample.area(ds)
    integral = fields.contact_stress.sum(("x", "y")) * dx * dy
    mass = fields.density.sum(("x", "y")) * dx * dy * fields.attrs["thickness_m"]
    exactness = {"stress": float(abs(integral - love_weber).max() / abs(love_weber).max()),
                 "mass": float(abs(mass / ds["mass"].sum() - 1).max())}

    res = window_cg(ds)
    r = fields.isel(time=res).compute()   # the residual fields, once
    inside = interior(r)
    local = field_invariants(r).q_over_p.where(inside)
    syy = scalar_field(r, "sigma_yy").where(inside)
    nu = r.solid_fraction.where(inside)
    kinetic = field_invariants(r, "kinetic").p.where(inside).mean()
    contact = field_invariants(r, "contact").p.where(inside).mean()
    rate = scalar_field(r.mean("time"), "shear_rate").where(inside.all("time"))
    ranked = np.sort(rate.values[np.isfinite(rate.values)])[::-1]
    table = {
        "snapshots": int(res.size),
        "q/p of the whole sample": float(ds.grain.stress_invariants().q_over_p.isel(time=res).mean()),
        "local q/p: mean": float(local.mean()),
        "local q/p: spatial std": float(local.std(("x", "y")).mean()),
        "sigma_yy: spatial std / mean": float((syy.std(("x", "y")) / syy.mean(("x", "y"))).mean()),
        "solid fraction: mean": float(nu.mean()),
        "solid fraction: spatial std": float(nu.std(("x", "y")).mean()),
        "kinetic / contact pressure": float(kinetic / contact),
        "shear rate of the mean flow: max / mean": float(rate.max() / rate.mean()),
        "area carrying half the shear rate": float(np.searchsorted(np.cumsum(ranked), 0.5 * ranked.sum()) / ranked.size),
    }

    bands = {}
    inside_all = inside.all("time")
    velocity = r.velocity
    parts = {"window": slice(None), "first half": slice(0, res.size // 2), "second half": slice(res.size // 2, None)}
    for part, cut in parts.items():
        part_rate = scalar_field(xr.Dataset({"velocity": velocity.isel(time=cut).mean("time")}), "shear_rate")
        band = find_shear_band(part_rate, inside=inside_all)
        bands[part] = {
            "found": bool(band.found),
            "angle to x (deg)": float(band.angle),
            "angle to the horizontal (deg)": float(min(band.angle, 180 - band.angle)),
            "offset (m)": float(band.offset),
            "width at half maximum (m)": float(band.fwhm),
            "width / mean diameter": float(band.fwhm) / mean_diameter(ds),
            "share of the shear rate": float(band.share),
            "area fraction": float(band.area_fraction),
            "rate in the strip / mean": float(band.inside_ratio),
            "rate outside / mean": float(band.outside_ratio),
            "contrast": float(band.contrast),
        }
    del r, velocity

    widths = {}
    d = mean_diameter(ds)
    part = ds.isel(time=res)
    for factor in (0.5, 1.0, 2.0, 4.0):
        f = part.grain.coarse_grained(width=factor * d)
        local = field_invariants(f).q_over_p.where(interior(f, margin=2 * d))
        widths[f"w = {factor} d"] = float(local.std(("x", "y")).mean())
    return {"exactness": exactness, "table": table, "bands": bands, "widths": widths}


def window_cg(ds):
    """coarse_graining.ipynb's window: the residual snapshots, or the second half of the run."""
    from grainview.analysis.strain import residual_window

    res = np.flatnonzero(residual_window(ds).values)
    return res if res.size else np.arange(ds.sizes["time"] // 2, ds.sizes["time"])


# --- notebooks/force_chains.ipynb ---------------------------------------------------------------

def axial_mean_deg(angles) -> float:
    return float(np.degrees(0.5 * np.arctan2(np.nanmean(np.sin(2 * angles)), np.nanmean(np.cos(2 * angles)))) % 180)


def force_chains(ds) -> dict:
    """The notebook's summary (cell 4) and lifetimes (cell 10), and docs/analysis.md's other rows."""
    from grainview.analysis.strain import residual_window

    out = ds.grain.force_chains(follow=True)
    inside = residual_window(ds).values
    if not inside.any():
        eps_q = ds.grain.strains()["eps_q"].values
        inside = eps_q >= 0.7 * eps_q.max()
    res = out.isel(time=np.flatnonzero(inside))
    summary = {"snapshots": int(res.sizes["time"]), "chains": float(res.n_chains.mean()),
               "mean length (particles)": float(res.mean_length.mean()),
               "share of particles": float(res.particle_fraction.mean()),
               "share of q": float(res.deviator_fraction.mean()),
               "share of p": float(res.pressure_fraction.mean()),
               "orientation (deg)": axial_mean_deg(res.orientation.values)}
    count = res.length_count.sum("time")
    lengths = res["length"].values
    theta = ds.grain.stress_invariants()["theta_sigma"].isel(time=np.flatnonzero(inside)).values
    extra = {"chains: sd over the snapshots": float(res.n_chains.std(ddof=1)),
             "share of particles: sd": float(res.particle_fraction.std(ddof=1)),
             "share of q: sd": float(res.deviator_fraction.std(ddof=1)),
             "share of p: sd": float(res.pressure_fraction.std(ddof=1)),
             "chains of 3 particles (pooled)": float(count.sel(length=3) / count.sum()),
             "chains of 20 or more (pooled)": float(count.values[lengths >= 20].sum() / count.sum()),
             "major stress direction (deg)": axial_mean_deg(theta)}

    alive = ~out.censored.values
    eps_q = ds.grain.strains()["eps_q"].values
    longest = int(np.argmax(out.lifetime.values))
    lives = {"chains followed": int(out.sizes["track"]), "born and gone within the run": int(alive.sum()),
             "mean lifetime (snapshots)": float(out.lifetime.values[alive].mean()),
             "seen in one snapshot only": float((out.lifetime.values[alive] == 1).mean()),
             "longest (snapshots)": int(out.lifetime.values.max()),
             "eps_q between snapshots": float(np.diff(eps_q).mean()),
             "longest: eps_q span": float(eps_q[int(out.last.values[longest])] - eps_q[int(out.first.values[longest])])}
    return {"summary": summary, "extra": extra, "lives": lives}


# --- notebooks/network_topology.ipynb -----------------------------------------------------------

def network_topology(ds) -> dict:
    """The notebook's table (cells 5 and 8), beta_0 at 0.5, loops per snapshot, 4-cliques."""
    eps_q = ds.grain.strains()["eps_q"].values
    keep = np.flatnonzero(eps_q >= 0.3) if eps_q.max() >= 0.3 else np.arange(int(0.7 * eps_q.size), eps_q.size)
    residual = ds.isel(time=keep)
    r = residual.grain.network_persistence().compute()
    n = residual.sizes["particle"]
    b0 = r["beta_0"].mean("time")
    row = {"snapshots": r.sizes["time"],
           "beta_0 at xi = 0": float(b0.sel(xi=0.0)), "beta_0 at xi = 1": float(b0.sel(xi=1.0)),
           "beta_0 peak": float(b0.max()), "xi of the peak": float(b0.idxmax("xi"))}
    b1 = r["beta_1"].mean("time")
    whole = float(b1.sel(xi=0.0))
    row.update({"beta_1/N at xi = 0": whole / n, "beta_1/N at xi = 1": float(b1.sel(xi=1.0)) / n,
                "xi where beta_1 halves": float(b1["xi"][int(np.argmax(b1.values <= whole / 2))])})
    loops = (r["dimension"] == 1)
    row["loops filled (per snapshot)"] = float((loops & np.isfinite(r["death"])).sum()) / r.sizes["time"]
    c3, c4 = r["cycles_3"].mean("time").values, r["cycles_4"].mean("time").values
    row.update({"3-cycles/N": c3.sum() / n, "4-cycles/N": c4.sum() / n,
                "3-cycles with >= 2 strong": c3[2:].sum() / c3.sum(), "4-cycles with >= 2 strong": c4[2:].sum() / c4.sum()})
    row = {k: float(v) for k, v in row.items()}
    extra = {"beta_0 at xi = 0.5": float(b0.sel(xi=0.5, method="nearest")),
             "beta_1 at xi = 0 (loops per snapshot)": whole,
             "beta_1 at xi = 1 / at xi = 0": float(b1.sel(xi=1.0)) / whole,
             "4-cliques (every snapshot of the run)": four_cliques(ds)}
    return {"table": row, "extra": extra}


def four_cliques(ds) -> int:
    """The 4-cliques of the force-bearing particle-particle contacts, summed over every snapshot."""
    from grainview.analysis.contacts import selection

    total = 0
    n_steps = ds.sizes["time"]
    for start in range(0, n_steps, 20):
        part = ds.isel(time=slice(start, start + 20))
        mask = selection(part).transpose("time", "contact").values
        i, j = (part[name].transpose("time", "contact").values for name in ("i", "j"))
        for t in range(mask.shape[0]):
            a, b = i[t][mask[t]], j[t][mask[t]]
            neighbours: dict[int, set] = {}
            for u, v in zip(a.tolist(), b.tolist()):
                if u != v:
                    neighbours.setdefault(u, set()).add(v)
                    neighbours.setdefault(v, set()).add(u)
            found = set()
            for u, v in zip(a.tolist(), b.tolist()):
                common = sorted(neighbours[u] & neighbours[v])
                for x in range(len(common)):
                    for y in range(x + 1, len(common)):
                        if common[y] in neighbours[common[x]]:
                            found.add(tuple(sorted((u, v, common[x], common[y]))))
            total += len(found)
    return total


# --- the weak network, the fabric, a'(xi) -------------------------------------------------------

def weak_network(ds) -> dict:
    """Residual-state means: the weak fraction, q(1)/p, a, a'(0.05) and a'(0.1)."""
    from grainview.analysis.force_networks import contact_proportions
    from grainview.analysis.strain import residual_window

    res = ds.isel(time=np.flatnonzero(residual_window(ds).values))
    profile = ds.grain.xi_profile(xi=[0.05, 0.1, 1.0]).compute()
    prop = contact_proportions(res).mean("time").compute()
    return {"weak fraction (contact_proportions)": float(prop["weak_fraction"]),
            "weak fraction (xi-network at 1)": float(profile["contact_fraction"].sel(xi=1.0)),
            "q(1)/p": float(profile["q_over_p"].sel(xi=1.0)),
            "a' at xi = 0.05": float(profile["a_prime"].sel(xi=0.05)),
            "a' at xi = 0.1": float(profile["a_prime"].sel(xi=0.1)),
            "fabric a": float(res.grain.fabric_anisotropy()["a"].mean("time"))}


def measure(path: str) -> dict:
    import grainview

    ds = grainview.open_dataset(path)
    result = {}
    for name, function in (("coarse_graining", coarse_graining), ("force_chains", force_chains),
                           ("network_topology", network_topology), ("weak_network", weak_network)):
        started = time.perf_counter()
        result[name] = function(ds)
        print(f"  {name}: {time.perf_counter() - started:.0f} s", flush=True)
    ds.close()
    return result


# --- the spread -------------------------------------------------------------------------------

def flatten(value, prefix=()):
    if isinstance(value, dict):
        for key, item in value.items():
            yield from flatten(item, prefix + (key,))
    else:
        yield prefix, value


def summary(data: dict, current: str = "seed0") -> str:
    """Per quantity and shape: each run's value, min-max, mean and sd (n - 1), and the value of
    the run ``current`` when there is one."""
    runs = list(data)
    lines = [f"runs: {', '.join(runs)}" + (f"; in brackets: {current}" if current in runs else "")]
    for shape in SHAPES:
        lines.append(f"\n== {shape}")
        keys = [k for k, _ in flatten(data[runs[0]][shape])]
        for key in keys:
            values = []
            for run in runs:
                value = data[run][shape]
                for part in key:
                    value = value[part]
                values.append(value)
            name = " / ".join(key)
            if all(isinstance(v, bool) for v in values):
                lines.append(f"{name:78s} {values}  ({sum(values)} of {len(values)})")
                continue
            x = np.asarray(values, float)
            each = " ".join(f"{v:.4g}" for v in x)
            now = f" [{x[runs.index(current)]:.4g}]" if current in runs else ""
            lines.append(f"{name:78s} {each} | {x.min():.4g}-{x.max():.4g}{now}, "
                         f"{x.mean():.4g}" + (f" +- {x.std(ddof=1):.2g}" if x.size > 1 else ""))
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.study_spread", description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    m = sub.add_parser("measure", help="measure each run's files into a JSON file")
    m.add_argument("--run", action="append", required=True, metavar="NAME=DIR",
                   help="a study folder holding pentagons.nc and disks.nc (repeat per run)")
    m.add_argument("--out", required=True, help="the JSON file (read first: runs already in it are kept)")
    s = sub.add_parser("summary", help="print the spread of a measured JSON file")
    s.add_argument("json")
    s.add_argument("--current", default="seed0", help="the run whose value is shown beside the range (default seed0)")
    args = parser.parse_args(argv)
    if args.command == "summary":
        with open(args.json) as f:
            print(summary(json.load(f), args.current))
        return 0
    data = {}
    if os.path.exists(args.out):
        with open(args.out) as f:
            data = json.load(f)
    for spec in args.run:
        name, _, folder = spec.partition("=")
        if not folder:
            parser.error(f"--run {spec!r}: expected NAME=DIR")
        for shape in SHAPES:
            if shape in data.get(name, {}):
                continue
            path = os.path.join(folder, f"{shape}.nc")
            print(f"{name}: {path}", flush=True)
            data.setdefault(name, {})[shape] = measure(path)
            with open(args.out + ".tmp", "w") as f:
                json.dump(data, f, indent=1)
            os.replace(args.out + ".tmp", args.out)
    print(summary(data))
    return 0


if __name__ == "__main__":
    sys.exit(main())
