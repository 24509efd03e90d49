"""The report of an ensemble: the headline numbers of every run, reduced over the seeds of
each setting to mean +- spread with the number of seeds, next to the paper's values.

:func:`ensemble_table` computes :func:`grainview.app.report.run_summary` for every run of an
ensemble (:func:`grainview.analysis.ensemble.open_ensemble`) and groups the runs by ``group`` (the
parameters other than the seed). Each number is then the mean over the group's seeds, its
sample standard deviation (ddof = 1) and standard error, and the count of seeds that have it
(a run short of the residual window counts for none of the residual rows).
:func:`write_ensemble_report` writes that table (Markdown with "mean +- std (n seeds)", CSV
with every statistic, CSV of every run) and the figures of q/p and of the fabric anisotropy a
against eps_q as mean +- std bands.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from ..analysis.ensemble import run_dataset, seed_statistics
from ..contract.errors import ParameterError
from .report import INITIAL_ROWS, NOT_REACHED, PAPER, paper_key
from ..analysis.strain import RESIDUAL_STRAIN

DESCRIPTION = ("particles", "seed", "preparation", "residual window", "double-contact criterion")
"""Rows of a run's summary that describe it rather than measure it (left out of the statistics)."""
STATISTICS = ("mean", "std", "sem", "n")
"""Columns of each group in :func:`ensemble_table`'s numbers."""
REACHED = "residual window reached"
"""Column of :func:`run_table`: whether the run reaches the residual window."""


def run_table(ens, residual_strain: float = RESIDUAL_STRAIN, log=None) -> pd.DataFrame:
    """The headline numbers of every run (rows: runs named as ``run``; columns: the rows of
    :data:`grainview.app.report.PAPER`, NaN where a run has no number) with the run's ``group`` and
    whether it reaches the residual window (:data:`REACHED`). The residual rows are kept when
    a run does not reach the window, so that the report can say so; other rows without any
    number are left out."""
    from .report import run_summary

    rows, reached = {}, {}
    for k, name in enumerate(str(n) for n in ens["run"].values):
        if log is not None:
            log(f"run {k + 1}/{ens.sizes['run']}: {name}")
        summary = run_summary(run_dataset(ens, k), residual_strain)
        reached[name] = not str(summary["residual window"]).startswith(NOT_REACHED)
        rows[name] = {key: value for key, value in summary.items() if key in PAPER["pentagons"] and key not in DESCRIPTION}
    table = pd.DataFrame.from_dict(rows, orient="index")
    numbers = table.apply(pd.to_numeric, errors="coerce")
    missed = table.eq(NOT_REACHED).any()
    numbers = numbers.loc[:, numbers.notna().any() | missed]
    numbers.insert(0, "group", [str(g) for g in ens["group"].values])
    numbers.insert(1, REACHED, [reached[name] for name in numbers.index])
    return numbers


def ensemble_table(ens, residual_strain: float = RESIDUAL_STRAIN, log=None) -> tuple[pd.DataFrame, pd.DataFrame]:
    """``(statistics, runs)``: per group and headline number the mean, std (ddof = 1), sem and
    the number of seeds with a value (columns ``(group, statistic)``), and :func:`run_table`."""
    if "run" not in ens.dims:
        raise ParameterError("not an ensemble: expected open_ensemble's Dataset (a 'run' dimension)")
    runs = run_table(ens, residual_strain, log)
    values = runs.drop(columns=["group", REACHED])
    grouped = values.groupby(runs["group"], sort=False)
    n = grouped.count()
    std = grouped.std(ddof=1).where(n > 1)
    stats = {"mean": grouped.mean(), "std": std, "sem": std / np.sqrt(n), "n": n}
    table = pd.concat({name: frame.T for name, frame in stats.items()}, axis=1)
    table = table.swaplevel(0, 1, axis=1)
    table = table[[(g, s) for g in grouped.groups if g in n.index for s in STATISTICS]]
    return table, runs


def format_table(stats: pd.DataFrame, runs: pd.DataFrame | None = None,
                 residual_strain: float = RESIDUAL_STRAIN) -> pd.DataFrame:
    """The statistics as text, "mean +- std (n seeds)" per group, with the paper's column
    beside every group whose label names a shape of the paper.

    With ``runs`` (:func:`run_table`), a residual row of a group whose runs do not all reach
    the residual window (eps_q >= ``residual_strain``) says so, as the report of single runs
    does: "not reached (0 of 3 seeds reach eps_q >= 0.3)" when none does, "... (2 seeds; 1 not
    reached)" when some do."""
    columns = {}
    for group in dict.fromkeys(stats.columns.get_level_values(0)):
        s = stats[group]
        if runs is not None:
            members = runs[runs["group"] == group]
            missed = members[~members[REACHED].astype(bool)]
            total, short = len(members), len(missed)
        else:
            total = short = 0

        def cell(row):
            # a residual row: one the runs short of the window have no number of (not e.g. a whole-test row)
            residual = (row.name not in INITIAL_ROWS and short > 0 and row.name in missed
                        and bool(missed[row.name].isna().all()))
            if not np.isfinite(row["mean"]):
                if residual and short and short == total:
                    return f"{NOT_REACHED} (0 of {total} seeds reach eps_q >= {residual_strain:g})"
                return "-"
            spread = f" ± {row['std']:.3f}" if np.isfinite(row["std"]) else ""
            note = f"; {short} {NOT_REACHED}" if residual else ""
            return f"{row['mean']:.3f}{spread} ({int(row['n'])} seed{'s' if row['n'] != 1 else ''}{note})"

        columns[f"{group} (mean ± std)"] = s.apply(cell, axis=1)
        paper = PAPER.get(paper_key(group))
        if paper is not None:
            columns[f"{group} (paper)"] = pd.Series({k: paper.get(k, "-") for k in s.index})
    return pd.DataFrame(columns)


def write_ensemble_report(ens, out, residual_strain: float = RESIDUAL_STRAIN, overwrite: bool = False,
                          bins=None, log=None) -> dict:
    """Write the report of an ensemble into folder ``out``: ``headline.md`` (mean +- std over
    seeds, the paper's values), ``headline.csv`` (mean, std, sem, n per group), ``runs.csv``
    (every run), ``fig_ensemble_q_over_p`` and ``fig_ensemble_fabric_anisotropy`` (PNG, PDF;
    mean +- std bands on eps_q ``bins``, default 0.025 wide) and ``index.md``. Returns
    {"table": the text table, "statistics": the numbers, "files": [paths]}. A folder that holds
    a report is refused unless ``overwrite``."""
    import matplotlib.pyplot as plt

    from ..plot._style import save_figure
    from .report import file_link
    from ..plot.ensemble import seed_bands

    out = Path(out)
    if not overwrite and (out / "headline.csv").exists():
        raise FileExistsError(f"{out} already holds a report; pass overwrite=True to replace it")
    stats, runs = ensemble_table(ens, residual_strain, log)
    text = format_table(stats, runs, residual_strain)
    out.mkdir(parents=True, exist_ok=True)
    files = [out / "headline.csv", out / "runs.csv", out / "headline.md"]
    stats.to_csv(files[0])
    runs.to_csv(files[1])
    lines = ["| quantity | " + " | ".join(text.columns) + " |", "|---" * (len(text.columns) + 1) + "|"]
    lines += ["| " + " | ".join([str(idx), *(str(v) for v in row)]) + " |" for idx, row in text.iterrows()]
    files[2].write_text("\n".join(lines) + "\n")
    if bins is None:  # 0.025 wide, up to the first edge beyond the largest strain reached
        top = float(np.nanmax(ens.grain.strains()["eps_q"].values))
        bins = 0.025 * np.arange(0, int(np.floor(top / 0.025)) + 2)
    figures = {
        "q_over_p": (ens.grain.stress_invariants()["q_over_p"], "q/p"),
        "fabric_anisotropy": (ens.grain.fabric_anisotropy()["a"], "fabric anisotropy a"),
    }
    for name, (series, label) in figures.items():
        if log is not None:
            log(f"figure: {name} against eps_q, mean ± std over seeds")
        ax = seed_bands(seed_statistics(series, eps_q_bins=bins), label=label)
        files += save_figure(ax.figure, out / f"fig_ensemble_{name}")
        plt.close(ax.figure)
    groups = ", ".join(f"{g} ({int((runs['group'] == g).sum())} runs)" for g in dict.fromkeys(runs["group"]))
    index = ["# Ensemble report", "", f"{ens.sizes['run']} runs in {len(set(runs['group']))} group(s): {groups}. "
             f"Residual state: eps_q >= {residual_strain:g}; each number is the mean ± sample standard deviation "
             "over the seeds of a group, with the number of seeds that have it.", "",
             "- [headline.md](headline.md), numbers in [headline.csv](headline.csv) (mean, std, sem, n), every run "
             "in [runs.csv](runs.csv)",
             "- q/p against eps_q: [fig_ensemble_q_over_p.png](fig_ensemble_q_over_p.png)",
             "- fabric anisotropy a against eps_q: [fig_ensemble_fabric_anisotropy.png]"
             "(fig_ensemble_fabric_anisotropy.png)", "", "## Runs", ""]
    index += [f"- `{name}`: group {g}, file {file_link(src, out)}" for name, g, src in
              zip(ens["run"].values, ens["group"].values, ens["source"].values)]
    (out / "index.md").write_text("\n".join(index) + "\n")
    files.append(out / "index.md")
    return {"table": text, "statistics": stats, "files": files}
