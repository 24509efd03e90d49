"""The twelve-relation verdicts of benchmarks/fidelity/relations.py on hand-made summaries:
a packing built to satisfy a relation must pass it, and the same packing with the two shapes
swapped (or a value moved out of the paper's range) must fail it."""

import importlib.util
import os

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
PATH = os.path.join(HERE, "..", "..", "benchmarks", "fidelity", "relations.py")


@pytest.fixture(scope="module")
def relations():
    spec = importlib.util.spec_from_file_location("fidelity_relations", PATH)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def paper_like(shape, **changes):
    """A residual-state summary with the paper's values (pentagons or disks)."""
    if shape == "pentagon":
        s = {"q/p": 0.35, "solid fraction initial": 0.80, "z": 3.75, "a": 0.10, "a_n": 0.30, "a_t": 0.28,
             "prediction": 0.34, "alpha": 0.74, "q(xi<1)/p": 0.01, "weak": 0.58, "very weak": 0.32,
             "q_d/p": 0.24, "q_s/p": 0.10, "f_d": 0.6, "f_s": 0.4, "k_d^S": 0.6, "k_s^S": 0.3}
    else:
        s = {"q/p": 0.28, "solid fraction initial": 0.82, "z": 3.85, "a": 0.30, "a_n": 0.20, "a_t": 0.10,
             "prediction": 0.30, "alpha": 1.4, "q(xi<1)/p": -0.01, "weak": 0.62, "very weak": 0.10,
             "q_d/p": 0.0, "q_s/p": 0.28, "f_d": 0.0, "f_s": 1.0, "k_d^S": 0.0, "k_s^S": 1.0}
    s.update(changes)
    return s


def verdicts(relations, pentagons, disks):
    return {name: holds for name, _paper, _text, holds in relations.evaluate(pentagons, disks)}


def test_the_papers_values_satisfy_all_twelve(relations):
    result = verdicts(relations, [paper_like("pentagon")] * 3, [paper_like("disk")] * 3)
    assert len(result) == 12
    assert all(result.values()), [name for name, ok in result.items() if not ok]


def test_ordering_relations_fail_when_the_shapes_are_swapped(relations):
    result = verdicts(relations, [paper_like("pentagon", **{"q/p": 0.25, "z": 3.9, "a": 0.4, "alpha": 2.0})],
                      [paper_like("disk")])
    assert not result["q/p: P > D"]
    assert not result["z: P < D"]
    assert not result["fabric a: P < D"]
    assert not result["strong-force exponent alpha: P < D"]
    assert result["a_n: P > D"]  # an untouched relation still holds


def test_range_relations(relations):
    # harmonic prediction 12% above q/p: outside the paper's 10%
    result = verdicts(relations, [paper_like("pentagon", prediction=0.35 * 1.12)], [paper_like("disk")])
    assert not result["q/p within 10% of (a' + a_n + a_t)/2"]
    # the weak network carrying a fifth of the deviator is not "~0"
    result = verdicts(relations, [paper_like("pentagon", **{"q(xi<1)/p": 0.07})], [paper_like("disk")])
    assert not result["q(xi)/p ~ 0 for xi < 1"]
    # very weak fraction 0.12 in pentagons: below the paper's ~0.3
    result = verdicts(relations, [paper_like("pentagon", **{"very weak": 0.12})], [paper_like("disk")])
    assert not result["very weak: P > D, ~0.3 in P"]
    # a_t / a_n of the pentagons 0.3 (paper: ~1)
    result = verdicts(relations, [paper_like("pentagon", a_t=0.09)], [paper_like("disk", a_t=0.05)])
    assert not result["a_t: P > D, a_t ~ a_n (P), ~ a_n/2 (D)"]
    # double contacts carrying less than simple ones
    result = verdicts(relations, [paper_like("pentagon", **{"q_d/p": 0.08, "q_s/p": 0.19})], [paper_like("disk")])
    assert not result["P: q_d/p > q_s/p, f_d > f_s, k_s^S < k_d^S"]


def test_seed_statistics(relations):
    summaries = [{"z": 3.0}, {"z": 3.2}, {"z": 3.4}]
    mean, spread = relations.stats(summaries, "z")
    assert mean == pytest.approx(3.2)
    assert spread == pytest.approx(0.2)  # sample standard deviation (ddof = 1)
    assert relations.fmt(summaries, "z") == "3.20 ± 0.20"
    assert relations.fmt(summaries[:1], "z") == "3.00"
