"""benchmarks/solver_bench/peer_engines.py (section c of RESULTS.md): the floor-force errors, by
hand and on a small pile at rest."""

import numpy as np
import pytest

from .conftest import load_solver_bench


@pytest.fixture(scope="module")
def peer_engines():
    return load_solver_bench("peer_engines")


def test_floor_errors_by_hand(peer_engines):
    # two steps 10% over and under the weight: a perfect mean, a 10% error in every step
    mean, rms = peer_engines.floor_errors([1.1, 0.9])
    assert mean == pytest.approx(0.0, abs=1e-15)
    assert rms == pytest.approx(0.1, rel=1e-12)
    mean, rms = peer_engines.floor_errors([1.02, 1.02, 1.05, 0.99])
    assert mean == pytest.approx(0.02, rel=1e-12)
    assert rms == pytest.approx(np.sqrt((0.02 ** 2 + 0.02 ** 2 + 0.05 ** 2 + 0.01 ** 2) / 4), rel=1e-12)


def test_a_settled_pile_carries_its_weight_step_by_step(peer_engines, tmp_path):
    pile = peer_engines.settle_pile(40, "disk", 1500)
    # settled: at rest, and no overlap left for the recovery pass
    assert pile["settled"] and pile["settle_steps"] <= 1500
    assert pile["largest_overlap"] < 1e-4
    path = str(tmp_path / "pile.npz")
    peer_engines.save_pile(pile, path)
    assert "settle_steps" not in np.load(path)
    r = peer_engines._ours_on_pile(path, 20, 2000, 1e-6, 15)
    assert r["floor"].shape == (15,)
    mean, rms = peer_engines.floor_errors(r["floor"])
    # at rest and solved tightly, every step's floor force is the weight (to the solver's tolerance)
    assert rms < 1e-4
    # three sweeps a step leave each step's forces far from balancing the weight
    loose = peer_engines._ours_on_pile(path, 20, 3, None, 15)
    assert peer_engines.floor_errors(loose["floor"])[1] > 100 * rms
