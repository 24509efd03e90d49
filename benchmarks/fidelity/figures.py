"""Figures of the fidelity study (PNG next to RESULTS.md), one function per section."""

from __future__ import annotations

import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

COLOURS = {"pentagon": "tab:red", "disk": "tab:blue"}
PAPER_INITIAL = {"pentagon": (0.80, 3.20), "disk": (0.82, 3.95)}


def _save(fig, path):
    fig.savefig(path, dpi=130, bbox_inches="tight")
    plt.close(fig)
    return path


def preparations(rows, path):
    """Solid fraction and z of the compacted samples against the compaction friction, both
    shapes (mean over seeds, bars: min-max), with the paper's S1 and S2 as dashed lines.
    ``rows``: dicts with shape, friction, solid fraction, z, z near."""
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.5))
    for shape in ("pentagon", "disk"):
        mine = [r for r in rows if r["shape"] == shape]
        frictions = sorted({r["friction"] for r in mine})
        for ax, key, k in ((axes[0], "solid fraction", 0), (axes[1], "z", 1)):
            values = [[r[key] for r in mine if r["friction"] == f] for f in frictions]
            mean = np.array([np.mean(v) for v in values])
            err = np.array([[m - min(v), max(v) - m] for m, v in zip(mean, values)]).T
            ax.errorbar(frictions, mean, yerr=err, marker="o", color=COLOURS[shape], capsize=3,
                        label=f"{shape}s")
            if key == "z":
                near = [np.mean([r["z near"] for r in mine if r["friction"] == f]) for f in frictions]
                ax.plot(frictions, near, ls=":", marker="x", color=COLOURS[shape], label=f"{shape}s, near pairs counted")
            ax.axhline(PAPER_INITIAL[shape][k], color=COLOURS[shape], ls="--", lw=1,
                       label=f"paper, {'S1' if shape == 'pentagon' else 'S2'}")
    axes[0].set_ylabel("solid fraction after compaction")
    axes[1].set_ylabel("coordination number z after compaction")
    for ax in axes:
        ax.set_xlabel(r"grain friction during compaction $\mu_c$")
    axes[1].legend(fontsize=7)
    fig.suptitle("Initial states: 400 particles, 3 seeds, isotropic compaction at 10 kPa", fontsize=9)
    return _save(fig, path)


def evolutions(curves, path, title, quantities=("q/p", "a", "z")):
    """q/p, a and z against eps_q for several runs. ``curves``: (label, shape, series) with
    series from measure.strain_series; line styles tell the runs of one shape apart."""
    fig, axes = plt.subplots(1, len(quantities), figsize=(4 * len(quantities), 3.4))
    styles = ["-", "--", ":", "-.", (0, (1, 1))]
    count = {}
    for label, shape, series in curves:
        k = count.get(shape, 0)
        count[shape] = k + 1
        for ax, q in zip(axes, quantities):
            x, y = series["eps_q"], series[q]
            width = max(1, len(y) // 40)  # a running mean over ~1/40 of the run
            smooth = np.convolve(y, np.ones(width) / width, mode="valid")
            start = (width - 1) // 2
            ax.plot(x[start:start + smooth.size], smooth, color=COLOURS[shape], ls=styles[k % len(styles)], lw=1.2,
                    label=label)
    names = {"q/p": "$q/p$", "a": "fabric anisotropy $a$", "z": "coordination $z$", "a_n": "$a_n$",
             "a_t": "$a_t$", "very weak": "very weak fraction"}
    for ax, q in zip(axes, quantities):
        ax.set_xlabel(r"shear strain $\varepsilon_q$")
        ax.set_ylabel(names[q])
    axes[0].legend(fontsize=7)
    fig.suptitle(title, fontsize=9)
    return _save(fig, path)


def counting(rows, path):
    """z, very weak fraction and fabric a against the near-contact gap threshold (fraction of
    d_min), both shapes; ``rows``: dicts with shape, near (0 for force-bearing), z, very weak, a."""
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.4))
    paper = {"z": {"pentagon": 3.75, "disk": 3.85}, "very weak": {"pentagon": 0.32}}
    for shape in ("pentagon", "disk"):
        mine = sorted((r for r in rows if r["shape"] == shape), key=lambda r: r["near"])
        x = [100 * r["near"] for r in mine]
        for ax, key in zip(axes, ("z", "very weak", "a")):
            ax.errorbar(x, [r[key][0] for r in mine], yerr=[r[key][1] for r in mine], marker="o",
                        color=COLOURS[shape], capsize=3, label=f"{shape}s")
            if shape in paper.get(key, {}):
                ax.axhline(paper[key][shape], color=COLOURS[shape], ls="--", lw=1, label=f"paper, {shape}s")
    for ax, key in zip(axes, ("coordination $z$", "very weak fraction ($f_n < 0.1 \\langle f_n\\rangle$)",
                              "fabric anisotropy $a$")):
        ax.set_xlabel(r"pairs counted up to a gap of (% of $d_{min}$; 0: force-bearing only)")
        ax.set_ylabel(key)
    axes[0].legend(fontsize=7)
    fig.suptitle("Residual state (eps_q >= 0.4), 1000 particles, 3 seeds: counting near pairs as contacts",
                 fontsize=9)
    return _save(fig, path)


def figure_path(output, name):
    return os.path.join(os.path.dirname(os.path.abspath(output)), f"fidelity_{name}.png")
