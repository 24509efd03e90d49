"""Force chains (Peters et al. 2005): hand-made packings whose chains are known, the kernel and
the particle stress against slow obviously-correct versions, the tracks on hand-made ids,
eager equal to chunked under a scheduler that raises on compute."""

from __future__ import annotations

from collections import deque

import numpy as np
import pytest
import xarray as xr

from grainview.analysis.arrays import force_chains as fc
from grainview.analysis.arrays.tensors import principal
from grainview.contract.dataset import make_dataset
from grainview.contract.errors import ParameterError
from grainview.analysis.force_chains import force_chains, particle_volume
from grainview.analysis.stress import stress_tensor
from grainview.analysis.sample import volume

from . import builders
from .builders import R
from .conftest import raise_if_dask_computes

VP = np.pi * R ** 2  # volume of a disk of radius R in a slab 1 m thick, m3


def column_among_pairs(load=10.0, light=0.5, n_column=5, n_pairs=3, rotation=0.0, tilt_deg=0.0):
    """A column of ``n_column`` disks carrying ``load`` N between a bottom and a top wall,
    beside ``n_pairs`` separate horizontal pairs pressed by ``light`` N; everything turned by
    ``rotation`` rad about the origin. Particles 0 .. n_column-1 are the column; its branch
    vectors alternate +-``tilt_deg`` from the vertical (0: a straight column), the wall
    contacts are vertical."""
    turn = np.array([[np.cos(rotation), -np.sin(rotation)], [np.sin(rotation), np.cos(rotation)]])
    t = np.deg2rad(tilt_deg)
    k = np.arange(n_column)
    column = np.stack([(k % 2) * 2 * R * np.sin(t), k * 2 * R * np.cos(t)], -1)
    pairs = np.concatenate([[[6 * R * (k + 1), 4 * R * k], [6 * R * (k + 1) + 2 * R, 4 * R * k]]
                            for k in range(n_pairs)])
    pos = np.concatenate([column, pairs]) @ turn.T
    n = len(pos)
    up = turn @ [0.0, 1.0]
    i = np.array(list(range(n_column - 1)) + [n_column + 2 * k for k in range(n_pairs)] + [0, n_column - 1])
    j = np.array(list(range(1, n_column)) + [n_column + 2 * k + 1 for k in range(n_pairs)] + [n, n + 1])
    branch = np.concatenate([pos[j[:-2]] - pos[i[:-2]], [-R * up, R * up]])
    normal = branch / np.linalg.norm(branch, axis=1, keepdims=True)
    fn = np.array([load] * (n_column - 1) + [light] * n_pairs + [load, load])
    point = pos[i] + R * normal
    contacts = [dict(i=i, j=j, kind=np.ones(i.size, "i1"), normal=normal, fn=fn, ft=np.zeros(i.size),
                     branch=branch, point=point)]
    lo, hi = pos.min(0) - 2 * R, pos.max(0) + 2 * R
    return make_dataset(radius=np.full(n, R), position=pos, contacts=contacts, box_min=lo, box_max=hi, n_walls=2)


def zigzag(tilt_deg=30.0, n=6):
    """:func:`column_among_pairs` with a zigzag column of ``n`` disks carrying 1 N, beside three
    pairs pressed by 0.05 N."""
    return column_among_pairs(load=1.0, light=0.05, n_column=n, tilt_deg=tilt_deg)


def confined_hexagonal(nx=6, ny=5, force=1.0):
    """Disks on a triangular lattice of spacing 2R, every nearest-neighbour contact carrying
    ``force`` N and every missing neighbour of a border disk replaced by a wall contact of the
    same force along the same direction (six walls, one per lattice direction): every disk is
    pressed alike from all six directions, an isotropic load."""
    a = 2 * R
    pos = np.array([[a * (x + 0.5 * (y % 2)), a * np.sqrt(3) / 2 * y] for y in range(ny) for x in range(nx)])
    n = len(pos)
    directions = np.array([[np.cos(k * np.pi / 3), np.sin(k * np.pi / 3)] for k in range(6)])
    i, j, normal, branch = [], [], [], []
    for p in range(n):
        for w, d in enumerate(directions):
            target = pos[p] + a * d
            hit = np.flatnonzero(np.linalg.norm(pos - target, axis=1) < 1e-9 * a)
            if hit.size and hit[0] > p:
                i.append(p); j.append(hit[0]); normal.append(d); branch.append(a * d)
            elif not hit.size:
                i.append(p); j.append(n + w); normal.append(d); branch.append(R * d)
    i, j, normal, branch = map(np.array, (i, j, normal, branch))
    contacts = [dict(i=i, j=j, kind=np.ones(i.size, "i1"), normal=normal, fn=np.full(i.size, force),
                     ft=np.zeros(i.size), branch=branch, point=pos[i] + R * normal)]
    return make_dataset(radius=np.full(n, R), position=pos, contacts=contacts, box_min=pos.min(0) - R,
                        box_max=pos.max(0) + R, n_walls=6, wall_names=[f"w{k}" for k in range(6)],
                        n_contact_slots=i.size)  # walls on every side: more than a planar graph's slots


def series(*snapshots):
    """The snapshots (one-snapshot datasets of the same particles) as one series."""
    out = xr.concat(list(snapshots), "time", data_vars="minimal", coords="minimal", compat="override")
    return out.assign_coords(time=np.arange(len(snapshots), dtype=float))


# -- the hand-made packings ---------------------------------------------------------------------

def test_a_loaded_column_among_lightly_loaded_pairs_is_one_chain(prepare):
    ds = prepare(column_among_pairs(load=10.0, light=0.5))
    with raise_if_dask_computes():
        out = ds.grain.force_chains()
    out = out.compute().isel(time=0)
    np.testing.assert_array_equal(out.chain.values, [0] * 5 + [-1] * 6)
    assert int(out.n_chains) == 1
    assert float(out.mean_length) == 5.0
    assert float(out.particle_fraction) == pytest.approx(5 / 11, rel=1e-15)
    assert int(out.length_count.sel(length=5)) == 1 and int(out.length_count.sum()) == 1
    assert float(out.length_pdf.sel(length=5)) == 1.0
    assert float(out.orientation) == pytest.approx(np.pi / 2, abs=1e-12)
    # column disks: two vertical contacts of 10 N at arm R; pair disks: one horizontal of 0.5 N
    np.testing.assert_allclose(out.sigma_1.values, [2 * 10.0 * R / VP] * 5 + [0.5 * R / VP] * 6, rtol=1e-12)
    np.testing.assert_allclose(out.theta_1.values[:5], np.pi / 2, atol=1e-12)
    # sums of V_p sigma_p: A = 5 * 2 * 10 R (yy) in the column, B = 6 * 0.5 R (xx) in the pairs;
    # deviators diag(-A, A)/2 and diag(B - A, A - B)/2: share A / (A - B), and A / (A + B) of p
    a, b = 100 * R, 3 * R
    assert float(out.deviator_fraction) == pytest.approx(a / (a - b), rel=1e-12)
    assert float(out.pressure_fraction) == pytest.approx(a / (a + b), rel=1e-12)
    # the four column contacts are the links, not the walls' nor the pairs'
    np.testing.assert_array_equal(np.flatnonzero(out.link.values), [0, 1, 2, 3])


@pytest.mark.parametrize("light", [0.5, 2.0])
def test_the_chains_contribution_to_q_exceeds_1_when_the_rest_opposes_it(light):
    """The column carries a vertical deviator, the horizontal pairs outside the chain a
    horizontal one, which lowers q: the chains' contribution to q is above 1 and the other
    particles' is negative, the two adding up to 1. The other particles' contribution is
    built here from their principal stresses, apart from the kernel's sums."""
    out = force_chains(column_among_pairs(load=10.0, light=light)).isel(time=0)
    outside = out.chain.values < 0
    np.testing.assert_array_equal(np.flatnonzero(outside), np.arange(5, 11))
    s1, s2, th = out.sigma_1.values, out.sigma_2.values, np.nan_to_num(out.theta_1.values)
    c, s = np.cos(th), np.sin(th)
    rot = np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)  # (P, 2, 2)
    tensors = VP * rot @ (np.stack([s1, s2], -1)[..., None] * np.eye(2)) @ np.swapaxes(rot, -1, -2)

    def dev(t):
        return t - 0.5 * np.trace(t) * np.eye(2)

    total, rest = dev(tensors.sum(0)), dev(tensors[outside].sum(0))
    rest_contribution = float((rest * total).sum() / (total * total).sum())
    a, b = 100 * R, 6 * light * R  # the column's yy sum, the pairs' xx sum (as above)
    assert rest_contribution == pytest.approx(-b / (a - b), rel=1e-12) and rest_contribution < 0
    assert float(out.deviator_fraction) == pytest.approx(1 - rest_contribution, rel=1e-12)
    assert float(out.deviator_fraction) == pytest.approx(a / (a - b), rel=1e-12) and a / (a - b) > 1
    assert 0 < float(out.pressure_fraction) < 1
    assert "above 1 where the other particles' deviator opposes it" in out.deviator_fraction.attrs["long_name"]


@pytest.mark.parametrize("rotation", [0.3, 1.1, 2.5])
def test_a_turned_column_is_the_same_chain_along_its_direction(rotation):
    out = force_chains(column_among_pairs(rotation=rotation)).isel(time=0)
    np.testing.assert_array_equal(out.chain.values, [0] * 5 + [-1] * 6)
    assert float(out.orientation) == pytest.approx(np.mod(np.pi / 2 + rotation, np.pi), abs=1e-12)


def test_the_particle_stress_is_per_unit_volume_of_the_slab():
    # a slab 0.25 m thick: the same forces spread over a quarter of the volume, four times the stress
    thin = column_among_pairs()
    thin.attrs["thickness_m"] = 0.25
    out = force_chains(thin).isel(time=0)
    np.testing.assert_allclose(out.sigma_1.values, [4 * 2 * 10.0 * R / VP] * 5 + [4 * 0.5 * R / VP] * 6, rtol=1e-12)
    np.testing.assert_allclose(particle_volume(thin).values, 0.25 * VP, rtol=1e-15)


def test_a_column_of_two_is_no_chain():
    out = force_chains(column_among_pairs(n_column=2)).isel(time=0)
    assert int(out.n_chains) == 0 and (out.chain.values == -1).all()
    assert float(out.deviator_fraction) == 0.0 and np.isnan(out.orientation)
    # with chains of two allowed, the column is one
    out = force_chains(column_among_pairs(n_column=2), min_size=2).isel(time=0)
    np.testing.assert_array_equal(out.chain.values[:2], [0, 0])


def test_the_angle_criterion_on_a_zigzag_column():
    # inner disks: two contacts at +-30 deg from the vertical, major direction vertical, so each
    # branch vector is 30 deg off it; end disks: 15 deg off (a vertical wall contact and one at 30)
    column = [0] * 6 + [-1] * 6
    np.testing.assert_array_equal(force_chains(zigzag(30.0), angle=45).chain.values[0], column)
    np.testing.assert_array_equal(force_chains(zigzag(30.0), angle=31).chain.values[0], column)
    assert (force_chains(zigzag(30.0), angle=29).chain.values == -1).all()
    # a straight column's links are at 0 deg from every major direction: any angle keeps them
    np.testing.assert_array_equal(force_chains(zigzag(0.0), angle=1).chain.values[0], column)
    # the mean orientation of two links at 60 and two at 120 deg: vertical
    assert float(force_chains(zigzag(30.0, n=5)).orientation[0]) == pytest.approx(np.pi / 2, abs=1e-12)


def test_an_isotropic_pile_has_no_chain(prepare):
    eager = confined_hexagonal()
    ds = prepare(eager)
    with raise_if_dask_computes():
        out = ds.grain.force_chains()
    out = out.compute().isel(time=0)
    # every disk: six contacts of 1 N at arm R, 60 deg apart: sigma = 3 R / V_p (1 0; 0 1)
    np.testing.assert_allclose(out.sigma_1.values, 3 * R / VP, rtol=1e-12)
    np.testing.assert_allclose(out.sigma_2.values, 3 * R / VP, rtol=1e-12)
    assert np.isnan(out.theta_1.values).all()
    assert int(out.n_chains) == 0 and (out.chain.values == -1).all() and not out.link.values.any()
    assert float(out.particle_fraction) == 0.0 and float(out.deviator_fraction) == 0.0


def test_an_isotropic_particle_above_the_mean_links_nothing(prepare):
    """A horizontal column of five disks pressed end to end by 10 N, its middle disk also pressed
    by 10 N from above and below (two walls), beside three vertical pairs at 0.5 N: the middle
    disk's stress is isotropic, 20 R/V_p (1 0; 0 1), above the mean of sigma_1 but without a
    major direction, so it links nothing and the column breaks into two pieces of two."""
    n_column, n = 5, 11
    column = np.array([[2 * R * k, 0.0] for k in range(n_column)])
    pairs = np.concatenate([[[4 * R * k, 6 * R], [4 * R * k, 8 * R]] for k in range(3)])
    pos = np.concatenate([column, pairs])
    x, y = np.array([1.0, 0.0]), np.array([0.0, 1.0])
    i = np.array([0, 1, 2, 3, 5, 7, 9, 0, 4, 2, 2])
    j = np.array([1, 2, 3, 4, 6, 8, 10, n, n + 1, n + 2, n + 3])
    normal = np.array([x] * 4 + [y] * 3 + [-x, x, y, -y])
    branch = np.concatenate([pos[j[:7]] - pos[i[:7]], R * normal[7:]])
    fn = np.array([10.0] * 4 + [0.5] * 3 + [10.0] * 4)
    contacts = [dict(i=i, j=j, kind=np.ones(i.size, "i1"), normal=normal, fn=fn, ft=np.zeros(i.size),
                     branch=branch, point=pos[i] + R * normal)]
    eager = make_dataset(radius=np.full(n, R), position=pos, contacts=contacts, box_min=pos.min(0) - 2 * R,
                         box_max=pos.max(0) + 2 * R, n_walls=4, wall_names=["left", "right", "top", "bottom"])
    out = prepare(eager).grain.force_chains().compute().isel(time=0)
    np.testing.assert_allclose(out.sigma_1.values[2], 20 * R / VP, rtol=1e-12)
    np.testing.assert_allclose(out.sigma_2.values[2], 20 * R / VP, rtol=1e-12)
    assert out.sigma_1.values[2] > out.sigma_1.values.mean() and np.isnan(out.theta_1.values[2])
    assert int(out.n_chains) == 0 and not out.link.values.any()
    pieces = force_chains(eager, min_size=2).isel(time=0)  # chains of two: the column's two halves
    np.testing.assert_array_equal(pieces.chain.values[:5], [0, 0, -1, 1, 1])
    np.testing.assert_array_equal(fc.chain_particles([3.0, 3.0, 1.0, 1.0], [3.0, 1.0, 1.0, 0.0]),
                                  [False, True, False, False])


def test_the_particle_stresses_add_up_to_the_sample_stress():
    # sum_p V_p sigma_p = sum_c f (x) l = V sigma (walls included): two independent sums
    ds = builders.mixed_contacts(seed=3, t=4)
    out = ds.grain.force_chains()
    mask = (ds.i >= 0) & (ds.fn > 0)
    moments = fc.particle_moments(ds.i.values, ds.j.values, ds.fn.values, ds.ft.values, ds.normal.values,
                                  ds.point.values, mask.values, ds.position.values)
    expected = (stress_tensor(ds) * volume(ds)).values
    np.testing.assert_allclose(moments.sum(-3), expected, rtol=1e-12, atol=1e-15)
    # and the principal values of the result are those of the moments over V_p
    s1, s2, _ = principal(moments / particle_volume(ds).values[:, None, None])
    np.testing.assert_allclose(out.sigma_1.values, s1, rtol=1e-12)
    np.testing.assert_allclose(out.sigma_2.values, s2, rtol=1e-12)


# -- against slow, obviously-correct versions ------------------------------------------------------

def slow_components(i, j, link, n_particles, min_size):
    """Breadth-first search over the linked contacts of one snapshot."""
    neighbours = [[] for _ in range(n_particles)]
    for a, b, on in zip(i, j, link):
        if on:
            neighbours[a].append(b)
            neighbours[b].append(a)
    out = np.full(n_particles, -1)
    seen = np.zeros(n_particles, bool)
    following = 0
    for start in range(n_particles):
        if seen[start]:
            continue
        members, queue = [], deque([start])
        seen[start] = True
        while queue:
            p = queue.popleft()
            members.append(p)
            for q in neighbours[p]:
                if not seen[q]:
                    seen[q] = True
                    queue.append(q)
        if len(members) >= min_size:
            out[members] = following
            following += 1
    return out


def test_the_labelling_kernel_matches_a_breadth_first_search():
    rng = np.random.default_rng(4)
    n, c = 60, 90
    i = rng.integers(0, n, (7, c))
    j = rng.integers(0, n, (7, c))
    link = rng.uniform(size=(7, c)) < 0.45
    for min_size in (1, 2, 3, 5):
        got = fc.components(i, j, link, n, min_size)
        for r in range(7):
            np.testing.assert_array_equal(got[r], slow_components(i[r], j[r], link[r], n, min_size))


def numpy_moments(i, j, fn, ft, normal, point, mask, position):
    """The per-particle sums with np.add.at, one side of the contacts at a time."""
    n_time, n_part = position.shape[:2]
    out = np.zeros((n_time, n_part, 2, 2))
    force = np.stack([fn * normal[..., 0] - ft * normal[..., 1], fn * normal[..., 1] + ft * normal[..., 0]], -1)
    for body, sign in ((i, 1.0), (j, -1.0)):
        t, c = np.nonzero(mask & (body >= 0) & (body < n_part))
        p = body[t, c]
        np.add.at(out, (t, p), sign * force[t, c, :, None] * (point[t, c] - position[t, p])[:, None, :])
    return out


def numpy_links(i, j, branch, mask, candidate, theta, angle):
    """The link test with whole-array numpy operations."""
    n_part = candidate.shape[-1]
    pair = mask & (i >= 0) & (j >= 0) & (i < n_part) & (j < n_part)
    si, sj = np.where(pair, i, 0), np.where(pair, j, 0)
    u = branch / np.linalg.norm(branch, axis=-1, keepdims=True)
    out = pair & np.take_along_axis(candidate, si, -1) & np.take_along_axis(candidate, sj, -1)
    for s in (si, sj):
        t = np.take_along_axis(theta, s, -1)
        out &= np.abs(u[..., 0] * np.cos(t) + u[..., 1] * np.sin(t)) >= np.cos(np.deg2rad(angle))
    return out


def test_the_moment_and_link_kernels_match_numpy_versions():
    ds = builders.mixed_contacts(seed=8, n=25, m=40, t=4)
    args = [ds[name].values for name in ("i", "j", "fn", "ft", "normal", "point")]
    mask = ((ds.i >= 0) & (ds.fn > 0)).values
    moments = fc.particle_moments(*args, mask, ds.position.values)
    np.testing.assert_allclose(moments, numpy_moments(*args, mask, ds.position.values), rtol=1e-13, atol=1e-16)
    rng = np.random.default_rng(9)
    candidate = rng.uniform(size=(4, 25)) < 0.6
    theta = rng.uniform(0, np.pi, (4, 25))
    for angle in (10.0, 45.0, 80.0):
        got = fc.chain_links(args[0], args[1], ds.branch.values, mask, candidate, theta, angle)
        want = numpy_links(args[0], args[1], ds.branch.values, mask, candidate, theta, angle)
        np.testing.assert_array_equal(got, want)
        assert want.any() and not want.all()


def slow_chains(snap, angle):
    """Peters et al.'s steps written out particle by particle for one snapshot."""
    n = snap.sizes["particle"]
    pos = snap.position.values
    moment = np.zeros((n, 2, 2))
    used = []
    for c in range(snap.sizes["contact"]):
        i, j, fn, ft = int(snap.i[c]), int(snap.j[c]), float(snap.fn[c]), float(snap.ft[c])
        if i < 0 or not fn > 0:
            continue
        nx, ny = snap.normal.values[c]
        f = np.array([fn * nx - ft * ny, fn * ny + ft * nx])
        moment[i] += np.outer(f, snap.point.values[c] - pos[i])
        if j < n:
            moment[j] -= np.outer(f, snap.point.values[c] - pos[j])
            used.append((i, j, snap.branch.values[c]))
    major, direction = np.zeros(n), np.zeros((n, 2))
    isotropic = np.zeros(n, bool)
    for p in range(n):
        values, vectors = np.linalg.eigh(0.5 * (moment[p] + moment[p].T) / (np.pi * R ** 2))
        major[p], direction[p] = values[1], vectors[:, 1]
        isotropic[p] = values[1] - values[0] <= fc.ISOTROPY_TOLERANCE * abs(values[1])
    strong = (major > major.mean()) & ~isotropic
    limit = np.cos(np.deg2rad(angle))
    link = [strong[i] and strong[j] and all(abs(np.dot(b / np.linalg.norm(b), direction[p])) >= limit for p in (i, j))
            for i, j, b in used]
    return slow_components([u[0] for u in used], [u[1] for u in used], link, n, 3)


@pytest.mark.parametrize("angle", [20.0, 45.0, 70.0])
def test_chains_match_a_particle_by_particle_version(angle):
    ds = builders.mixed_contacts(seed=5, n=40, m=70, t=5)
    out = force_chains(ds, angle=angle)
    assert out.n_chains.values.sum() > 0  # the case has chains to compare
    for k in range(ds.sizes["time"]):
        np.testing.assert_array_equal(out.chain.values[k], slow_chains(ds.isel(time=k), angle))


# -- following chains ----------------------------------------------------------------------------

def numpy_follow(chain):
    """Tracks with np.unique and np.lexsort, snapshot by snapshot (the mutual best matches)."""
    chain = np.asarray(chain, np.int64)
    n_time = chain.shape[0]
    track = np.full(chain.shape, -1, np.int64)
    first, last, total = [], [], []
    previous = np.zeros(0, np.int64)  # track of each chain id of the previous snapshot
    for t in range(n_time):
        ids = chain[t]
        n_here = int(ids.max()) + 1 if ids.size else 0
        mapping = np.full(max(n_here, 0), -1, np.int64)
        if t > 0 and n_here > 0 and previous.size > 0:
            both = (chain[t - 1] >= 0) & (ids >= 0)
            code, shared = np.unique(chain[t - 1][both] * n_here + ids[both], return_counts=True)
            if code.size:
                a, b = code // n_here, code % n_here
                best_b = np.lexsort((b, -shared, a))  # per a: most shared first, then smallest b
                keep_a = np.r_[True, a[best_b][1:] != a[best_b][:-1]]
                best_a = np.lexsort((a, -shared, b))
                keep_b = np.r_[True, b[best_a][1:] != b[best_a][:-1]]
                mutual = np.intersect1d(best_b[keep_a], best_a[keep_b])
                mapping[b[mutual]] = previous[a[mutual]]
        for k in np.flatnonzero(mapping < 0):
            mapping[k] = len(first)
            first.append(t)
            last.append(t)
            total.append(0)
        sizes = np.bincount(ids[ids >= 0], minlength=n_here)
        for k in range(n_here):
            last[mapping[k]] = t
            total[mapping[k]] += sizes[k]
        track[t] = np.where(ids >= 0, mapping[np.maximum(ids, 0)] if n_here else -1, -1)
        previous = mapping
    first = np.asarray(first, np.int64)
    last = np.asarray(last, np.int64)
    return track, first, last, np.asarray(total, float) / np.maximum(last - first + 1, 1)
def test_the_tracking_kernel_matches_a_numpy_version():
    rng = np.random.default_rng(11)
    chain = -np.ones((40, 60), np.int64)
    order = rng.permutation(60)
    for t in range(40):  # chains drawn as runs of a shuffled order, kept in part from one row to the next
        if rng.uniform() < 0.3:
            order = rng.permutation(60)
        cuts = np.sort(rng.choice(np.arange(1, 60), rng.integers(3, 12), replace=False))
        for k, part in enumerate(np.split(order, cuts)):
            if part.size >= 3 and rng.uniform() < 0.7:
                chain[t, part] = k
        ids = np.unique(chain[t][chain[t] >= 0])  # renumber 0, 1, ... like force_chains
        chain[t] = np.where(chain[t] >= 0, np.searchsorted(ids, chain[t]), -1)
    chain[7] = -1  # a snapshot without chains
    got = fc.follow_chains(chain)
    want = numpy_follow(chain)
    for g, w in zip(got, want):
        np.testing.assert_array_equal(g, w)
    assert got[1].size > 40 and (got[2] > got[1]).any()  # many tracks, some longer than a snapshot


def test_tracks_follow_shared_members():
    ids = -np.ones((4, 10), int)
    ids[0, [0, 1, 2]] = 0; ids[0, [5, 6, 7]] = 1          # two chains
    ids[1, [0, 1, 2, 3]] = 0; ids[1, [6, 7, 8]] = 1       # both go on
    ids[2, [0, 1, 2, 6, 7]] = 0                           # they merge: the first (3 shared) goes on
    ids[3, [4, 8, 9]] = 0                                 # a new one; the merged one is gone
    track, first, last, size = fc.follow_chains(ids)
    np.testing.assert_array_equal(track[1], ids[1])
    np.testing.assert_array_equal(track[2][[0, 1, 2, 6, 7]], 0)
    np.testing.assert_array_equal(track[3][[4, 8, 9]], 2)
    np.testing.assert_array_equal(first, [0, 0, 3])
    np.testing.assert_array_equal(last, [2, 1, 3])
    np.testing.assert_allclose(size, [(3 + 4 + 5) / 3, 3, 3])


def test_a_split_chain_goes_on_in_its_larger_part_and_ties_go_to_the_smaller_id():
    ids = -np.ones((3, 8), int)
    ids[0, :7] = 0
    ids[1, [0, 1, 2]] = 0; ids[1, [3, 4, 5, 6]] = 1       # the larger part (id 1) goes on
    ids[2, [0, 1, 2]] = 1; ids[2, [3, 4, 5]] = 0          # ...
    track, first, last, _ = fc.follow_chains(ids)
    np.testing.assert_array_equal(track[1][[0, 3]], [1, 0])
    np.testing.assert_array_equal(track[2][[0, 3]], [1, 0])
    np.testing.assert_array_equal(first, [0, 1])
    ids = -np.ones((2, 6), int)
    ids[0, :6] = 0
    ids[1, [0, 1, 2]] = 1; ids[1, [3, 4, 5]] = 0          # a tie: the smaller id (0) goes on
    track, _, _, _ = fc.follow_chains(ids)
    np.testing.assert_array_equal(track[1], [1, 1, 1, 0, 0, 0])


def test_follow_gives_lifetimes(prepare):
    column = column_among_pairs()
    none = column_among_pairs(load=0.2)  # the column below the mean (0.4 R/V_p against 0.5 R/V_p): no chain
    ds = prepare(series(column, column, none, column))
    out = ds.grain.force_chains(follow=True)
    np.testing.assert_array_equal(out.n_chains.values, [1, 1, 0, 1])
    np.testing.assert_array_equal(out.chain_track.values[:, 0], [0, 0, -1, 1])
    np.testing.assert_array_equal(out.lifetime.values, [2, 1])
    np.testing.assert_array_equal(out.duration.values, [1.0, 0.0])
    np.testing.assert_array_equal(out.censored.values, [True, True])
    np.testing.assert_array_equal(out.mean_size.values, [5.0, 5.0])


# -- laziness, and errors ------------------------------------------------------------------------

def test_eager_equals_chunked():
    eager = series(column_among_pairs(), column_among_pairs(rotation=0.4), column_among_pairs(load=0.2))
    chunked = eager.chunk({"time": 1})
    with raise_if_dask_computes():
        lazy = force_chains(chunked)
    assert lazy.chain.chunks is not None
    xr.testing.assert_identical(lazy.compute(), force_chains(eager))
    mixed = builders.mixed_contacts(seed=7, n=30, m=50, t=6)
    with raise_if_dask_computes():
        lazy = force_chains(mixed.chunk({"time": 2}), angle=60)
    xr.testing.assert_identical(lazy.compute(), force_chains(mixed, angle=60))


@pytest.mark.parametrize("kwargs, words", [
    (dict(angle=0), "angle=0"), (dict(angle=91), "0 < angle <= 90"), (dict(angle="45"), "angle='45'"),
    (dict(min_size=1), "min_size=1: expected an integer >= 2"),
    (dict(min_size=4, max_length=3), "max_length=3: expected an integer >= 4"),
])
def test_bad_parameters_are_named(kwargs, words):
    with pytest.raises(ParameterError, match=words):
        force_chains(column_among_pairs(), **kwargs)


def test_an_ensemble_gives_each_run_its_chains_and_tracks(tmp_path):
    # two runs of different lengths; with follow=True the tracks of each run along 'track'
    # (a per-particle variable named like that dimension broke the combination along 'run')
    import grainview
    from grainview.contract.dataset import netcdf_encoding

    runs = [series(column_among_pairs(), column_among_pairs(), column_among_pairs(load=0.2)),
            series(column_among_pairs(load=0.2), column_among_pairs())]
    paths = []
    for k, ds in enumerate(runs):
        ds.attrs.update(preparation_seed=np.int32(k))
        paths.append(tmp_path / f"run{k}.nc")
        ds.to_netcdf(paths[-1], encoding=netcdf_encoding(ds), format="NETCDF3_64BIT")
    out = grainview.open_ensemble(paths).grain.force_chains(follow=True)
    np.testing.assert_array_equal(out.n_chains.values[0], [1, 1, 0])
    np.testing.assert_array_equal(out.n_chains.values[1, :2], [0, 1])
    np.testing.assert_array_equal(out.lifetime.values[0, :1], [2])
    np.testing.assert_array_equal(out.lifetime.values[1, :1], [1])
    np.testing.assert_array_equal(out.chain_track.values[0, :, 0], [0, 0, -1])


# -- pooled over snapshots: P(L) and the chains' survival (drawn by plot/chains.py) -------------

def test_the_length_pdf_pools_the_chosen_snapshots_through_the_accessor(prepare):
    from grainview.analysis.force_chains import chain_length_pdf

    three = series(column_among_pairs(), column_among_pairs(rotation=0.4), column_among_pairs(load=0.2))
    lazy = prepare(three)
    with raise_if_dask_computes():
        pooled = lazy.grain.chain_length_pdf(time="all", max_length=8)
        none = chain_length_pdf(lazy, time=[2], max_length=8)
    count = pooled["length_count"].values
    assert count[list(pooled["length"].values).index(5)] == 2 and count.sum() == 2  # the column, twice
    np.testing.assert_array_equal(pooled["length_pdf"].values, np.where(pooled["length"].values == 5, 1.0, 0.0))
    assert pooled.attrs["pooled_snapshots"] == 3
    assert none["length_count"].values.sum() == 0 and np.isnan(none["length_pdf"].values).all()


def test_the_survival_counts_only_the_chains_born_and_gone_within_the_record():
    light, column = column_among_pairs(load=0.2), column_among_pairs()
    survival = series(light, column, light, column, column, light).grain.chain_survival()
    np.testing.assert_array_equal(survival["lifetime"].values, [1, 2])  # one chain of 1 snapshot, one of 2
    np.testing.assert_allclose(survival.values, [1.0, 0.5])
    assert survival.attrs["chains"] == 2
    censored = series(column, column, light).grain.chain_survival()  # seen in the first snapshot
    assert censored.size == 0 and censored.attrs["chains"] == 0
