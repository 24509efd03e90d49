"""The pentagons-versus-disks report: the paper's headline numbers next to a run's own, and
every figure the data supports.

:func:`headline_table` reduces each run to the numbers the paper quotes (docs/fidelity.md
lists them with the paper's sections), averaged over its *residual state*: the snapshots with
eps_q >= ``residual_strain`` (default 0.3, :func:`grainview.analysis.strain.residual_window`). A run
that stops short of it reports "not reached" for every residual value instead of another
state's average. The table also says what it describes: particles, seed, preparation, the
strain window and its snapshots, and the double-contact criterion of the run.
:func:`write_report` writes that table as CSV and Markdown and draws the figures.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import xarray as xr

from ..contract.errors import ParameterError
from ..analysis.strain import RESIDUAL_STRAIN, residual_window
from .table_text import format_cell

NOT_REACHED = "not reached"
"""Value of a residual-state row of a run that stops short of the residual window."""

PHI_0_ROW = "phi_0 = median(phi - psi), eps_q >= 0.02 (rad)"
"""Headline row of the stress–dilatancy offset of Fig. 5 (:func:`grainview.analysis.strain.friction_offset`),
over the whole test rather than the residual state."""

# The paper's values (Azema et al. 2007, Secs. III-VI; docs/fidelity.md); strings where the
# paper gives no number. k_d, q_s/p and q_d/p are implied rather than quoted: see
# docs/fidelity.md.
PAPER = {
    "pentagons": {
        "particles": 14400, "q/p (residual)": 0.35, "solid fraction (initial)": 0.80, "z (initial)": 3.20,
        PHI_0_ROW: "-",
        "z (residual)": 3.75, "z with walls (residual)": "-", "a (residual)": "small (nearly isotropic)",
        "a_n (residual)": "larger than disks", "a_t (residual)": "close to a_n",
        "(a' + a_n + a_t)/2 (residual)": "~q/p", "(a' + a_n + a_t)/(2 + a' a_n) (residual)": "-",
        "alpha (strong-force pdf)": 0.74, "weak fraction": 0.58,
        "very weak fraction": 0.32, "very weak simple": 0.25, "very weak double": 0.07,
        "z, near pairs (residual)": 3.75, "very weak fraction, near pairs": 0.32, "a, near pairs (residual)": "small",
        "k_s": "> k_d", "k_d": "~0.47 (implied)", "q_s/p": "q_d/p / 2-3", "q_d/p": "2-3 q_s/p", "f_d / f_s": 1.5,
        "k_s^S / k_d^S": 0.5, "k_s^W / k_d^W": 2.0,
    },
    "disks": {
        "particles": 10000, "q/p (residual)": 0.28, "solid fraction (initial)": 0.82, "z (initial)": 3.95,
        PHI_0_ROW: "-",
        "z (residual)": 3.85, "z with walls (residual)": "-", "a (residual)": "up to ~0.3",
        "a_n (residual)": "smaller than pentagons", "a_t (residual)": "about a_n/2",
        "(a' + a_n + a_t)/2 (residual)": "~q/p", "(a' + a_n + a_t)/(2 + a' a_n) (residual)": "-",
        "alpha (strong-force pdf)": 1.4, "weak fraction": 0.62,
        "very weak fraction": "-", "very weak simple": "-", "very weak double": "-",
        "z, near pairs (residual)": 3.85, "very weak fraction, near pairs": "-", "a, near pairs (residual)": "~0.3",
        "k_s": 1.0, "k_d": 0.0, "q_s/p": "= q/p", "q_d/p": 0.0, "f_d / f_s": "-", "k_s^S / k_d^S": "-",
        "k_s^W / k_d^W": "-",
    },
}

for _paper in PAPER.values():
    _paper.update({"seed": "-", "preparation": "geometric construction, isotropic compaction at 10 kPa",
                   "residual window": "eps_q >= ~0.3 (Figs. 7, 8, 10)",
                   "double-contact criterion": "LMGC90 shadow overlap (docs/fidelity.md)"})

INITIAL_ROWS = ("solid fraction (initial)", "z (initial)", PHI_0_ROW)
NEAR_FRACTION = 0.01
"""The report's near-contact rows count the pairs within this fraction of the smallest
diameter (docs/fidelity.md, section 5)."""
NEAR_ROWS = ("z, near pairs (residual)", "very weak fraction, near pairs", "a, near pairs (residual)")
"""Rows read on the first snapshot; every other number row is a residual-state mean."""


def _ratio(a, b):
    return float(a) / float(b) if float(b) != 0 else float("nan")


def describe_run(ds: xr.Dataset, window: xr.DataArray, residual_strain: float) -> dict:
    """The rows that say what a run is: particles, seed, preparation, window, criterion."""
    from ..analysis.sample import regular_of
    from .summary import shape_counts

    attrs = ds.attrs
    n_vertices = ds["n_vertices"].values
    eps_q = window["eps_q"] if "eps_q" in window.coords else None
    if bool(window.any()):
        lo = float(eps_q.where(window).min()) if eps_q is not None else residual_strain
        hi = float(eps_q.where(window).max()) if eps_q is not None else np.nan
        text = f"eps_q {lo:.2f}-{hi:.2f} ({int(window.sum())} snapshots)"
    else:
        top = float(eps_q.max()) if eps_q is not None else np.nan
        text = f"{NOT_REACHED}: eps_q >= {residual_strain:g} wanted, run ends at {top:.3f}"
    preparation = attrs.get("preparation_name", "unknown")
    alert = attrs.get("solver_alert")
    criterion = ("-" if not n_vertices.any() else
                 "two edges facing within the alert distance" + ("" if alert is None else f" ({float(alert) * 1e3:.2g} mm)"))
    return {
        "particles": shape_counts(n_vertices, regular_of(ds)),
        "seed": str(attrs.get("preparation_seed", attrs.get("solver_seed", "?"))),
        "preparation": str(preparation),
        "residual window": text,
        "double-contact criterion": criterion,
    }


def run_summary(ds: xr.Dataset, residual_strain: float = RESIDUAL_STRAIN) -> dict:
    """The headline numbers of one run (keys as in :data:`PAPER`), residual values averaged
    over the snapshots with eps_q >= ``residual_strain`` ("not reached" when there are none)."""
    from ..analysis.force_networks import contact_proportions
    from ..analysis.force_pdf import pooled_force_pdf, strong_force_exponent
    from ..analysis.strain import strains

    window = residual_window(ds, residual_strain)
    window = window.assign_coords(eps_q=strains(ds)["eps_q"].compute())
    out = describe_run(ds, window, residual_strain)
    out["solid fraction (initial)"] = float(ds.grain.solid_fraction().isel(time=0))
    out["z (initial)"] = float(ds.grain.coordination()["z"].isel(time=0))
    from ..analysis.strain import EARLY_STRAIN, friction_offset
    phi_0 = friction_offset(ds)  # Fig. 5's phi_0, over the whole test
    out[PHI_0_ROW] = phi_0 if np.isfinite(phi_0) else f"{NOT_REACHED}: eps_q < {EARLY_STRAIN:g} throughout"
    residual_rows = [key for key in PAPER["pentagons"] if key not in out and key not in INITIAL_ROWS]
    if not bool(window.any()):
        out.update({key: NOT_REACHED for key in residual_rows})
        return out
    res = ds.isel(time=np.flatnonzero(window.values))

    def mean(da):
        return float(da.mean("time").compute())

    prop = contact_proportions(res).mean("time").compute()
    alpha = strong_force_exponent(pooled_force_pdf(res, scale="linear", bins=40, range=(0.0, 6.0)))
    anis = res.grain.harmonic_prediction()
    inv = res.grain.stress_invariants()
    out.update({
        "q/p (residual)": mean(inv["q_over_p"]),
        "z (residual)": mean(res.grain.coordination()["z"]),
        "z with walls (residual)": mean(res.grain.coordination(walls=True)["z"]),
        "a (residual)": mean(res.grain.fabric_anisotropy()["a"]),
        "a_n (residual)": mean(anis["a_n"]),
        "a_t (residual)": mean(anis["a_t"]),
        "(a' + a_n + a_t)/2 (residual)": mean(anis["prediction"]),
        "(a' + a_n + a_t)/(2 + a' a_n) (residual)": mean(anis["prediction_cross_term"]),
        "alpha (strong-force pdf)": float(alpha),
        "weak fraction": float(prop["weak_fraction"]),
        "very weak fraction": float(prop["very_weak_fraction"]),
        "very weak simple": float(prop["very_weak_simple"]),
        "very weak double": float(prop["very_weak_double"]),
        "k_s": float(prop["k_s"]),
        "k_d": float(prop["k_d"]),
        "q_s/p": mean(res.grain.stress_invariants(kind="simple")["q_over_p"]),
        "q_d/p": mean(res.grain.stress_invariants(kind="double")["q_over_p"]),
        "f_d / f_s": _ratio(prop["f_d"], prop["f_s"]),
        "k_s^S / k_d^S": _ratio(prop["k_s_strong"], prop["k_d_strong"]),
        "k_s^W / k_d^W": _ratio(prop["k_s_weak"], prop["k_d_weak"]),
    })
    out.update(_near_rows(res))
    return out


def near_gap(runs: dict) -> float | None:
    """The report's near-pair gap (m): :data:`NEAR_FRACTION` of the smallest diameter over
    ``runs``, or None when one of them does not hold its near pairs up to that gap."""
    from ..analysis.contacts import check_near

    gap = NEAR_FRACTION * 2.0 * min(float(ds["radius"].min()) for ds in runs.values())
    try:
        for ds in runs.values():
            check_near(ds, gap)
    except ParameterError:
        return None
    return gap


def _near_rows(res: xr.Dataset) -> dict:
    """The residual z, very weak fraction and fabric a with the near pairs within
    :data:`NEAR_FRACTION` of the smallest diameter counted, when the file holds them ("-"
    otherwise)."""
    gap = near_gap({"run": res})
    if gap is None:
        return {key: "- (no near pairs in the file)" for key in NEAR_ROWS}
    prop = res.grain.contact_proportions(near=gap).mean("time").compute()
    return {
        "z, near pairs (residual)": float(res.grain.coordination(near=gap)["z"].mean("time")),
        "very weak fraction, near pairs": float(prop["very_weak_fraction"]),
        "a, near pairs (residual)": float(res.grain.fabric_anisotropy(near=gap)["a"].mean("time")),
    }


def headline_table(runs: dict, residual_strain: float = RESIDUAL_STRAIN) -> pd.DataFrame:
    """One row per headline quantity; for each run a column of its value and, where the run is
    one of the paper's samples, a column of the paper's value: "<label> (paper)" when its label
    names the sample ("pentagons", "disks", :func:`paper_key`), else "<label> (paper: <sample>)"
    when its particles do (:func:`paper_sample`).

    ``table.attrs["csv"]`` holds the rows that describe the runs as numbers, for
    :func:`write_table`'s CSV: ``{column: {row: number}}`` (:func:`description_numbers`)."""
    if not runs:
        raise ParameterError("runs is empty: expected {label: dataset}")
    columns, numbers = {}, {}
    for label, ds in runs.items():
        columns[f"{label} (this run)"] = run_summary(ds, residual_strain)
        numbers[f"{label} (this run)"] = description_numbers(ds, residual_strain)
        key = paper_key(label)
        name = f"{label} (paper)"
        if key is None:
            key = paper_sample(ds)
            name = f"{label} (paper: {key})"
        if key is not None:
            columns[name] = PAPER[key]
            numbers[name] = PAPER_NUMBERS[key]
    table = pd.DataFrame(columns)
    table.attrs["csv"] = numbers
    return table


PAPER_NUMBERS = {"pentagons": {"particles": 14400, "residual window from eps_q": 0.3},
                 "disks": {"particles": 10000, "residual window from eps_q": 0.3}}
"""The description rows of the paper's samples as numbers (:func:`description_numbers`)."""
CSV_DESCRIPTION = {"particles": ("particles",), "seed": ("seed",),
                   "residual window": ("residual window from eps_q", "residual window to eps_q",
                                       "residual window snapshots")}
"""The CSV's numeric rows in place of each description row of the table."""


def description_numbers(ds: xr.Dataset, residual_strain: float = RESIDUAL_STRAIN) -> dict:
    """The rows that describe a run, as numbers: its particle count, its seed (None when the
    file records none) and its residual window: first and last eps_q of the snapshots with
    eps_q >= ``residual_strain`` (None when none reaches it) and how many they are."""
    from ..analysis.strain import strains

    window = np.asarray(residual_window(ds, residual_strain).values, bool)
    inside = np.asarray(strains(ds)["eps_q"].values, float)[window]
    seed = ds.attrs.get("preparation_seed", ds.attrs.get("solver_seed"))
    try:
        seed = int(seed) if seed is not None and float(seed) == int(seed) else None
    except (TypeError, ValueError):
        seed = None
    return {"particles": int(ds.sizes["particle"]), "seed": seed,
            "residual window from eps_q": float(inside.min()) if inside.size else None,
            "residual window to eps_q": float(inside.max()) if inside.size else None,
            "residual window snapshots": int(inside.size)}


def paper_sample(ds: xr.Dataset) -> str | None:
    """The paper's sample whose particles a run has: "disks" (every particle a disk),
    "pentagons" (every particle a regular pentagon) or None."""
    from ..analysis.sample import shape_name

    return {"disk": "disks", "5-gon": "pentagons"}.get(shape_name(ds))


def paper_key(label: str) -> str | None:
    """The paper's sample a run label refers to: "pentagons" (S1), "disks" (S2) or None."""
    low = label.lower()
    if "pent" in low or "s1" in low:
        return "pentagons"
    if "disk" in low or "disc" in low or "s2" in low:
        return "disks"
    return None


def _number(value):
    """``value`` as an int or a finite float, or None when it is no number (text, NaN)."""
    if isinstance(value, (bool, np.bool_)):
        return None
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value) if np.isfinite(value) else None
    return None


def csv_table(table: pd.DataFrame) -> pd.DataFrame:
    """The numbers of ``table``, as :func:`write_table` writes them to CSV: ints stay ints,
    a cell that is not a number is None (empty), and the rows that describe the runs
    (particles, seed, residual window) are the numbers of ``table.attrs["csv"]``
    (:data:`CSV_DESCRIPTION`)."""
    numbers = table.attrs.get("csv", {})
    rows = {}
    for idx, row in table.iterrows():
        if idx in CSV_DESCRIPTION and numbers:
            for name in CSV_DESCRIPTION[idx]:
                rows[name] = {column: _number(numbers.get(column, {}).get(name)) for column in table.columns}
        else:
            rows[idx] = {column: _number(value) for column, value in row.items()}
    values = np.empty((len(rows), len(table.columns)), dtype=object)  # ints stay ints, None stays empty
    values[:] = [[row[column] for column in table.columns] for row in rows.values()]
    return pd.DataFrame(values, index=list(rows), columns=table.columns)


def write_table(table: pd.DataFrame, out: Path, notes=()) -> list[Path]:
    """Write ``table`` as ``headline.md`` (everything, prose included; ``notes``: paragraphs
    written under it) and ``headline.csv`` (numbers only, :func:`csv_table`: a cell that is
    not a number — "not reached", a qualitative statement of the paper — is empty there, so
    the file loads as floats; integers are written as integers, and the particles, the seed
    and the residual window are rows of numbers)."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    csv, md = out / "headline.csv", out / "headline.md"
    csv_table(table).to_csv(csv)

    lines = ["| quantity | " + " | ".join(table.columns) + " |", "|---" * (len(table.columns) + 1) + "|"]
    lines += ["| " + " | ".join([str(idx), *(format_cell(v) for v in row)]) + " |" for idx, row in table.iterrows()]
    for note in notes:
        lines += ["", note]
    md.write_text("\n".join(lines) + "\n")
    return [csv, md]


POLYGON_FIGURES = ("18", "19", "20", "21", "22", "23", "24", "25")
"""Figures about simple versus double contacts (paper Sec. VI): drawn for polygon runs only."""
MAP_FIGURES = ("02", "13", "17", "24")
"""Maps of one snapshot of one sample: the report's ``time`` (default the last); Fig. 2, the
packing at the end of the isotropic compaction, the first snapshot."""
PER_RUN_FIGURES = MAP_FIGURES + ("21",)
"""Figures that draw one sample per call: one file per run."""
DISTRIBUTION_FIGURES = ("07", "08", "10", "14", "15", "16", "21", "23")
"""Figures that average distributions over the residual state (their ``time`` argument)."""

FIGURE_NAMES = {
    "02": "packing", "03": "q_over_p", "04": "volumetric_strain", "05": "stress_dilatancy", "06a": "coordination",
    "06b": "persistence", "07": "connectivity", "08": "orientation_pdf", "09": "fabric_anisotropy",
    "10": "angular_forces", "11": "force_anisotropies", "12": "harmonic_prediction", "13": "force_chains",
    "14": "force_pdfs", "15": "xi_stress", "16": "xi_anisotropy", "17": "force_classes",
    "18": "partial_q_over_p", "19": "contact_proportions", "20": "type_transitions",
    "21": "joint_connectivity", "22": "partial_fabric_anisotropy", "23": "force_pdfs_by_kind",
    "24": "contact_kinds", "25": "strong_weak_proportions",
}


def _slug(label: str) -> str:
    return "".join(c if c.isalnum() else "_" for c in label).strip("_").lower() or "run"


def caption(label: str, ds: xr.Dataset, what: str, residual_strain: float = RESIDUAL_STRAIN, time=-1) -> str:
    """One line saying what a figure shows of run ``label``: N and shape, seed, preparation,
    and, by ``what``: "map" the snapshot drawn, "distribution" the residual window averaged
    over, anything else the range of the evolution."""
    from ..analysis.sample import regular_of
    from ..analysis.snapshots import residual_snapshots
    from ..analysis.strain import strains
    from .summary import shape_counts

    shape = shape_counts(ds["n_vertices"].values, regular_of(ds))
    seed = ds.attrs.get("preparation_seed", ds.attrs.get("solver_seed", "?"))
    preparation = ds.attrs.get("preparation_name", "unknown")
    eps_q = strains(ds)["eps_q"]
    if what == "map":
        index = time % ds.sizes["time"] if isinstance(time, (int, np.integer)) else time
        shown = f"snapshot {index} of {ds.sizes['time']} (eps_q = {float(eps_q.isel(time=time)):.3f})"
    elif what == "distribution":
        shown = f"averaged over the {residual_snapshots(ds, residual_strain).attrs['window']}"
    else:
        shown = f"every snapshot, eps_q 0-{float(eps_q.max()):.2f} ({ds.sizes['time']} snapshots)"
    return f"{label}: {shape}, seed {seed}, preparation '{preparation}'; {shown}"


def check_figures(numbers) -> tuple:
    """The paper figure numbers ``numbers`` (e.g. ``("03", "13")``; ``3`` and ``"3"`` are read as
    ``"03"``) as the report names them, refused in one line when one is not a figure it draws;
    None: every figure."""
    from ..plot import FIGURES

    if numbers is None:
        return tuple(FIGURES)
    chosen = []
    for number in numbers:
        text = str(number).strip().lower()
        name = next((n for n in FIGURES if n.lstrip("0") == text.lstrip("0")), None) if text else None
        if name is None:
            raise ParameterError(f"figures={text!r}: expected paper figure numbers among {', '.join(FIGURES)}")
        chosen.append(name)
    if not chosen:
        raise ParameterError(f"figures=(): expected at least one of {', '.join(FIGURES)}")
    return tuple(dict.fromkeys(chosen))


def write_figures(runs: dict, out: Path, time=-1, residual_strain: float = RESIDUAL_STRAIN, log=None,
                  captions: dict | None = None, figures=None) -> list[Path]:
    """Draw every figure of the paper the runs support into ``out`` (PNG and PDF), or only the
    paper figure numbers ``figures`` (:func:`check_figures`; for large runs, where each figure
    takes minutes).

    Comparative figures get all runs on one axes; the maps and P(m_s, m_d) one file per run
    (snapshot ``time``, default the last); the simple-versus-double figures only the runs
    that contain polygons. Returns the paths written. ``log``: called with one line per figure
    (progress); ``captions``: filled with {file stem: caption lines}.
    """
    import matplotlib.pyplot as plt  # any backend: matplotlib falls back to Agg without a display

    from ..plot import FIGURES, save_figure
    from ..analysis.snapshots import Residual
    from ..plot._style import add_caption
    from ..plot.captions import STRAIN_FIGURES, describe_figure, interval_note, sampling_note, strain_note

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    polygon_runs = {k: v for k, v in runs.items() if int(v["n_vertices"].max()) > 0}
    drawn = check_figures(figures)
    written = []
    for number, func in FIGURES.items():
        if number not in drawn:
            continue
        chosen = polygon_runs if number in POLYGON_FIGURES else runs
        if not chosen:
            continue
        name = f"fig{number}_{FIGURE_NAMES[number]}"
        targets = ([(f"{name}_{_slug(label)}", {label: ds}) for label, ds in chosen.items()]
                   if number in PER_RUN_FIGURES else [(name, chosen)])
        if number == "13":  # the maps of every run on one width scale, so that they compare
            width_scale, width_rule = common_force_scale(chosen, time)
        for stem, data in targets:
            kwargs = {}
            shown = 0 if number == "02" else time  # Fig. 2: the compacted sample, before the test
            if number in MAP_FIGURES:
                kwargs["time"] = shown
            elif number in DISTRIBUTION_FIGURES:
                kwargs["time"] = Residual(residual_strain)
            rule = None
            if number == "16":
                kwargs["near"], rule = xi_contacts(data)
            if number == "13":
                kwargs["force_scale"], rule = width_scale, width_rule
            result = func(data if number not in PER_RUN_FIGURES else next(iter(data.values())), **kwargs)
            fig = result if hasattr(result, "savefig") else result.figure
            what = "map" if number in MAP_FIGURES else "distribution" if number in DISTRIBUTION_FIGURES else "evolution"
            lines = [describe_figure(number)] + [caption(label, ds, what, residual_strain, shown)
                                                 for label, ds in data.items()]
            if rule is not None:
                lines.append(rule)
            if number == "08":  # why P(theta) has spikes: the pooled snapshots share their contacts
                lines += [sampling_note(label, ds, residual_strain) for label, ds in data.items()]
            if number == "20":  # Delta gamma depends on the interval between snapshots
                lines += [interval_note(label, ds) for label, ds in data.items()]
            if number in STRAIN_FIGURES:  # where eps_q decreases, the curves fold back
                lines += [note for note in (strain_note(label, ds) for label, ds in data.items()) if note]
            add_caption(fig, lines)
            if captions is not None:
                captions[stem] = lines
            if log is not None:
                log(f"figure {number} ({FIGURE_NAMES[number]}): {stem}.png")
            save_figure(fig, out / stem)
            plt.close(fig)
            written += [out / f"{stem}.png", out / f"{stem}.pdf"]
    return written


def common_force_scale(runs: dict, time=-1):
    """The force (N) drawn at the widest line in every run's force-chain map (Fig. 13): the
    largest particle–particle normal force of snapshot ``time`` over all runs, so that equal
    widths mean equal forces from one map to the next. Returns ``(force, caption line)``."""
    from ..analysis.contacts import selection
    from ..plot.maps import FORCE_UNIT, per_metre

    largest = 0.0
    for ds in runs.values():
        snap = ds.isel(time=time)
        fn = snap["fn"].where(selection(snap)).max()
        largest = max(largest, float(fn) if np.isfinite(float(fn)) else 0.0)
    names = ", ".join(runs)
    thickness = float(next(iter(runs.values())).attrs.get("thickness_m", 1.0))
    return largest, (f"line widths on one scale for {names}: the widest line is {per_metre(largest, thickness)} "
                     f"({FORCE_UNIT})")


def xi_contacts(runs: dict):
    """The contacts of the xi-network's fabric (Fig. 16) and the caption line that says so.

    When every run holds its near pairs, those within :data:`NEAR_FRACTION` of the smallest
    diameter are counted with the force-bearing contacts, as a code that keeps its alert-distance
    pairs counts them (docs/fidelity.md, section 5). Counted on their own, the force-bearing
    contacts include pairs just closing along the compression axis with forces far below the
    solver's resolution, which lift a'(xi) at the smallest cutoffs (docs/analysis.md).
    Returns ``(near, line)``: the gap in m (None: force-bearing only) and the caption line."""
    gap = near_gap(runs)
    if gap is None:
        return None, "contacts: force-bearing only (f_n > 0; the files hold no near pairs)"
    return gap, (f"contacts: force-bearing and the pairs within {gap * 1e3:.2g} mm "
                 f"({NEAR_FRACTION:g} of the smallest diameter), which carry no force")


def write_report(runs: dict, out, residual_strain: float = RESIDUAL_STRAIN, overwrite: bool = False,
                 log=None, figures=None) -> dict:
    """The whole report of ``runs`` ({label: dataset}) in folder ``out``: the headline table
    (CSV, Markdown), every figure (or the paper figure numbers ``figures``,
    :func:`check_figures`), and ``index.md`` (each run's settings, the table, every figure with
    its caption). Returns {"table": DataFrame, "files": [paths]}. ``log``: called with a line
    per stage and figure (the command line prints them).

    A folder that already holds a report is refused unless ``overwrite`` is True, so that
    nothing a user owns is replaced by accident."""
    out = Path(out)
    figures = check_figures(figures)  # before any work
    if not overwrite and (out / "headline.csv").exists():
        raise FileExistsError(f"{out} already holds a report; pass overwrite=True to replace it")
    if log is not None:
        log(f"headline table of {len(runs)} run(s) (residual window eps_q >= {residual_strain:g}) ...")
    table = headline_table(runs, residual_strain)
    files = write_table(table, out, notes=convergence_notes(runs))
    captions = {}
    files += write_figures(runs, out / "figures", residual_strain=residual_strain, log=log, captions=captions,
                           figures=figures)
    files.append(write_index(runs, out, captions, residual_strain))
    return {"table": table, "files": files}


def convergence_text(ds: xr.Dataset) -> str:
    """What a run's file says of its steps whose NLGS did not converge, and how far their
    impulses were from a solution (:func:`grainview.app.convergence.unconverged_text`): the
    test's steps (its snapshots' counts), then, for a biaxial test whose file records them,
    its compaction's (:func:`grainview.app.convergence.compaction_text`), the two counted
    apart as the command that ran it counts them."""
    from .convergence import compaction_in_file, compaction_text, unconverged_in_file, unconverged_text

    biaxial = ds.attrs.get("scene") == "biaxial"
    text = unconverged_text(unconverged_in_file(ds, ds.attrs), "the test" if biaxial else "the run")
    compaction = compaction_text(compaction_in_file(ds.attrs)) if biaxial else ""
    return f"{text} {compaction}" if compaction else text


def convergence_notes(runs: dict) -> list[str]:
    """The paragraphs under the headline table: each run's :func:`convergence_text`."""
    return [f"**{label}.** {convergence_text(ds)}" for label, ds in runs.items()]


def file_link(source, folder) -> str:
    """A Markdown link to file ``source`` from a page in ``folder``: the path relative to
    ``folder``, so that it resolves wherever the two are moved together; "(in memory)" for
    no file."""
    import os
    from urllib.parse import quote

    if not source:
        return "(in memory)"
    relative = Path(os.path.relpath(os.path.abspath(source), os.path.abspath(folder))).as_posix()
    return f"[{relative}]({quote(relative)})"


def write_index(runs: dict, out: Path, captions: dict, residual_strain: float = RESIDUAL_STRAIN) -> Path:
    """``out/index.md``: the runs (their settings, :func:`grainview.app.summary.describe`), the
    headline table, and every figure file with its caption, in the paper's order."""
    from .summary import describe

    out = Path(out)
    lines = ["# Report", "", "Force transmission in the runs below, next to Azema, Radjai, Peyroux & Saussine, "
             "Phys. Rev. E 76, 011301 (2007). Residual state: eps_q >= " + f"{residual_strain:g}.", "", "## Runs", ""]
    for label, ds in runs.items():
        lines += [f"### {label}", "", f"File: {file_link(ds.encoding.get('source'), out)}", ""] + [f"- {line}" for line in describe(ds)]
        lines += [f"- {convergence_text(ds)}", ""]
    lines += ["## Headline table", "", "[headline.md](headline.md) (numbers only: [headline.csv](headline.csv))", "",
              "## Figures", ""]
    for stem, caption_lines in captions.items():
        number = stem[3:].split("_")[0]
        lines += [f"- **Fig. {number.lstrip('0')}** [{stem}.png](figures/{stem}.png) ([pdf](figures/{stem}.pdf)): "
                  + "; ".join(caption_lines)]
    path = out / "index.md"
    path.write_text("\n".join(lines) + "\n")
    return path
