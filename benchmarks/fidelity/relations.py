"""The twelve relations between the pentagon (P) and disk (D) packings that the paper reports,
each a test on residual-state means that holds or fails.

Every relation takes the per-seed summaries of both shapes (lists of dicts from
:func:`measure.window_means`) and returns ``(this study's value as text, holds)``. Seeds give a
mean and a spread (sample standard deviation); a comparison between shapes holds when the
means are in the paper's order, and the text shows both means with their spreads so that a
reader can see whether the gap exceeds the scatter.
"""

from __future__ import annotations

import numpy as np


def stats(summaries, key):
    """Mean and sample standard deviation of ``key`` over seeds (spread 0 for one seed)."""
    values = np.array([s[key] for s in summaries], float)
    spread = float(values.std(ddof=1)) if values.size > 1 else 0.0
    return float(values.mean()), spread


def fmt(summaries, key, digits=2):
    mean, spread = stats(summaries, key)
    return f"{mean:.{digits}f} ± {spread:.{digits}f}" if len(summaries) > 1 else f"{mean:.{digits}f}"


def _compare(key, pentagons_larger):
    def relation(p, d):
        mp, md = stats(p, key)[0], stats(d, key)[0]
        holds = mp > md if pentagons_larger else mp < md
        return f"P {fmt(p, key)}, D {fmt(d, key)}", holds
    return relation


def _ratio_text(summaries, num, den):
    ratios = [s[num] / s[den] for s in summaries]
    return float(np.mean(ratios)), f"{np.mean(ratios):.2f}"


def _a_t(p, d):
    rp, tp = _ratio_text(p, "a_t", "a_n")
    rd, td = _ratio_text(d, "a_t", "a_n")
    holds = stats(p, "a_t")[0] > stats(d, "a_t")[0] and 0.75 <= rp <= 1.25 and 0.35 <= rd <= 0.65
    return f"P {fmt(p, 'a_t')} (a_t/a_n {tp}), D {fmt(d, 'a_t')} (a_t/a_n {td})", holds


def _harmonic(p, d):
    """The paper's first-order form decides; the text adds the form with the cross term
    a' a_n (docs/conventions.md §3), where the summaries have it."""
    texts, holds = [], True
    for name, s in (("P", p), ("D", d)):
        off = np.mean([x["prediction"] / x["q/p"] - 1 for x in s])
        text = f"{name} {off:+.0%}"
        if all("prediction cross" in x for x in s):
            text += f" ({np.mean([x['prediction cross'] / x['q/p'] - 1 for x in s]):+.0%} with the cross term)"
        texts.append(text)
        holds &= abs(off) <= 0.10
    return "prediction / (q/p) - 1: " + ", ".join(texts), bool(holds)


def _xi(p, d):
    texts, holds = [], True
    for name, s in (("P", p), ("D", d)):
        share = np.mean([x["q(xi<1)/p"] / x["q/p"] for x in s])
        texts.append(f"{name} {share:+.2f}")
        holds &= abs(share) <= 0.10
    return "q(xi=1)/q: " + ", ".join(texts), bool(holds)


def _weak(p, d):
    mp, md = stats(p, "weak")[0], stats(d, "weak")[0]
    return f"P {fmt(p, 'weak')}, D {fmt(d, 'weak')}", bool(0.55 <= mp <= 0.65 and 0.55 <= md <= 0.65)


def _very_weak(p, d):
    mp, md = stats(p, "very weak")[0], stats(d, "very weak")[0]
    return f"P {fmt(p, 'very weak')}, D {fmt(d, 'very weak')}", bool(mp > md and 0.25 <= mp <= 0.35)


def _double(p, d):
    qd, qs = stats(p, "q_d/p")[0], stats(p, "q_s/p")[0]
    fd, fs = stats(p, "f_d")[0], stats(p, "f_s")[0]
    kd, ks = stats(p, "k_d^S")[0], stats(p, "k_s^S")[0]
    text = (f"q_d/p {qd:.2f} vs q_s/p {qs:.2f}; f_d {fd:.2f} vs f_s {fs:.2f}; "
            f"k_s^S {ks:.2f} vs k_d^S {kd:.2f}")
    return text, bool(qd > qs and fd > fs and ks < kd)


RELATIONS = [
    ("q/p: P > D", "0.35 > 0.28", _compare("q/p", True)),
    ("solid fraction (initial): P < D", "0.80 < 0.82", _compare("solid fraction initial", False)),
    ("z: P < D", "3.75 < 3.85", _compare("z", False)),
    ("fabric a: P < D", "P nearly isotropic, D ~0.3", _compare("a", False)),
    ("a_n: P > D", "P > D", _compare("a_n", True)),
    ("a_t: P > D, a_t ~ a_n (P), ~ a_n/2 (D)", "P > D; a_t/a_n ~1 (P), ~0.5 (D)", _a_t),
    ("q/p within 10% of (a' + a_n + a_t)/2", "holds for P and D", _harmonic),
    ("strong-force exponent alpha: P < D", "0.74 < 1.4", _compare("alpha", False)),
    ("q(xi)/p ~ 0 for xi < 1", "~0 for P and D", _xi),
    ("weak fraction 0.55-0.65", "0.58 (P), 0.62 (D)", _weak),
    ("very weak: P > D, ~0.3 in P", "0.32 (P)", _very_weak),
    ("P: q_d/p > q_s/p, f_d > f_s, k_s^S < k_d^S", "q_d ~2-3 q_s; f_d ~1.5 f_s; k_s^S ~0.5 k_d^S", _double),
]
"""(relation, the paper's values, test) for each of the twelve relations."""


def evaluate(pentagons, disks):
    """[(relation, paper, this study's text, holds)] for per-seed summaries of both shapes."""
    return [(name, paper, *test(pentagons, disks)) for name, paper, test in RELATIONS]
