"""Near contacts: pairs within the alert distance that carry no force are written on request,
with their gap, and nowhere else change the file (restart impulses stay aligned)."""

import numpy as np
import pytest

import grainview
from solver import Parameters, Simulation, Walls
from solver.output import Recorder, pair_contacts, point_impulses, written_pairs

R = 0.0125
ALERT = 0.02 * 2 * R  # the default alert distance: 2% of the smallest diameter


def _three_disks_on_a_floor(gap_near, gap_far):
    """Zero gravity. Disks 0, 1, 2 touch the floor (gap 0, no force) in a row, disk 1 at
    ``gap_near`` to the right of disk 0 and disk 2 at ``gap_far`` to the right of disk 1;
    disk 3, above disk 0 and touching it, moves down at 1 cm/s, so after one step the pairs
    (0, 3) and (0, floor) carry force and every other pair found carries none."""
    x1 = 2 * R + gap_near
    x2 = x1 + 2 * R + gap_far
    position = [[0.0, R], [x1, R], [x2, R], [0.0, 3 * R]]
    velocity = [[0.0, 0.0], [0.0, 0.0], [0.0, 0.0], [0.0, -0.01]]
    sim = Simulation(position, np.zeros(4), np.full(4, R), np.zeros(4, int), Walls.floor(),
                     Parameters(gravity=(0.0, 0.0)), velocity=velocity)
    sim.step()
    return sim


def test_near_pairs_inside_the_threshold_are_written_with_zero_force():
    sim = _three_disks_on_a_floor(gap_near=0.4 * ALERT, gap_far=1.5 * ALERT)
    assert sim.alert == pytest.approx(ALERT)
    loaded = pair_contacts(sim)
    # force-bearing: disk 3 pushed onto disk 0, disk 0 onto the floor (body 4)
    pairs = set(zip(loaded["i"].tolist(), loaded["j"].tolist()))
    assert pairs == {(0, 3), (0, 4)}
    assert np.all(loaded["fn"] > 0)
    near = pair_contacts(sim, near=sim.alert)
    pairs_near = dict(zip(zip(near["i"].tolist(), near["j"].tolist()), range(len(near["i"]))))
    # the pair (0, 1) at 0.4 alert is written, with zero force and its gap; (1, 2) at 1.5 alert
    # is beyond the alert distance and was never a candidate; disks 1 and 2 on the floor touch it
    k = pairs_near[(0, 1)]
    assert near["fn"][k] == 0.0 and near["ft"][k] == 0.0
    assert near["gap"][k] == pytest.approx(0.4 * ALERT, rel=1e-9)
    assert (1, 2) not in pairs_near
    for pair in ((0, 3), (0, 4)):
        assert near["fn"][pairs_near[pair]] > 0
    # a threshold below the gap leaves the pair out
    tight = pair_contacts(sim, near=0.3 * ALERT)
    assert (0, 1) not in set(zip(tight["i"].tolist(), tight["j"].tolist()))


def test_near_pairs_keep_the_restart_impulses_aligned_with_their_slots():
    sim = _three_disks_on_a_floor(gap_near=0.4 * ALERT, gap_far=1.5 * ALERT)
    slots = 12
    for near in (None, sim.alert):
        c = pair_contacts(sim, near, slots)
        normal, _ = point_impulses(sim, slots, near)
        m = len(c["i"])
        # the impulse of each written slot is its force times the step; nothing beyond
        np.testing.assert_allclose(normal[:m].sum(1), c["fn"] * sim.parameters.time_step, rtol=1e-12)
        assert not normal[m:].any()


def test_near_pairs_that_do_not_fit_leave_out_the_farthest_first():
    sim = _three_disks_on_a_floor(gap_near=0.4 * ALERT, gap_far=1.5 * ALERT)
    everything = written_pairs(sim, near=sim.alert)
    with pytest.warns(RuntimeWarning, match="do not all fit"):
        fitted = written_pairs(sim, near=sim.alert, n_slots=int(everything.sum()) - 1)
    assert fitted.sum() == everything.sum() - 1
    assert np.all(fitted[written_pairs(sim)])  # force-bearing pairs are always kept


def test_a_run_written_with_near_contacts_counts_them_on_request(tmp_path):
    sim = _three_disks_on_a_floor(gap_near=0.4 * ALERT, gap_far=1.5 * ALERT)
    path = tmp_path / "near.nc"
    with Recorder(path, sim, near_contacts=True) as rec:
        rec.write()
    ds = grainview.open_dataset(path, chunks=None, validate=True)
    assert ds.attrs["near_contacts_m"] == pytest.approx(sim.alert)
    counts = ds.grain.contact_numbers(walls=True)
    near = ds.grain.contact_numbers(walls=True, near=0.5 * ALERT)
    # default: force-bearing only, (0, 3) and (0, floor)
    np.testing.assert_array_equal(counts.values[0], [2, 0, 0, 1])
    # near = 0.5 alert adds (0, 1) at 0.4 alert and the unloaded floor contacts of 1 and 2 (gap 0);
    # (1, 2) at 1.5 alert is beyond the alert distance and not in the file
    np.testing.assert_array_equal(near.values[0], [3, 2, 1, 1])
    # particle pairs only: disk 0 has (0, 1) and (0, 3), disks 1 and 3 one each, disk 2 none (rattler)
    assert float(ds.grain.coordination(near=0.5 * ALERT)["z"][0]) == pytest.approx((2 + 1 + 1) / 3)
    assert float(ds.grain.coordination()["z"][0]) == pytest.approx(1.0)
    ds.close()
