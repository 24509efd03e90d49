"""Example datasets of the contract drawn from the harmonic model (docs/conventions.md §3).

Used by the demo, the tests and the analysis benchmarks: contacts whose orientation density
is P(theta) = (1/pi)[1 + a cos 2(theta - theta_0)], normal forces
<f_n>(theta) = <f>[1 + a_n cos 2(theta - theta_0)] times an exponential spread, and tangential
forces <f_t>(theta) = -<f> a_t sin 2(theta - theta_0) that resist the shear, so that q/p is
close to (a + a_n + a_t)/2.
"""

from __future__ import annotations

import numpy as np

from .contract.dataset import make_dataset

PAIR_LENGTH_M = 0.02
SOLID_FRACTION = 0.1
"""Area fraction of the particles in the first snapshot's box (the pairs are scattered, not
packed); the box grows with the number of contacts to keep it."""


def harmonic_contacts(n, a, a_n, a_t, theta_0=0.0, mean_force=1.0, rng=None, double_fraction=0.3,
                      spread="uniform"):
    """Arrays (normal, fn, ft, kind) of ``n`` contacts drawn from the harmonic model.

    ``spread`` multiplies each normal force by a random factor of mean 1: "uniform" on
    [0.5, 1.5], or "exponential" (a granular-like pdf).
    """
    rng = np.random.default_rng(rng)
    theta = np.empty(0)
    while theta.size < n:  # rejection sampling of P(theta)
        draw = rng.uniform(0, np.pi, 2 * n)
        keep = rng.uniform(0, 1 + abs(a), draw.size) < 1 + a * np.cos(2 * (draw - theta_0))
        theta = np.concatenate([theta, draw[keep]])
    theta = theta[:n]
    normal = np.stack([np.cos(theta), np.sin(theta)], -1)
    factor = rng.uniform(0.5, 1.5, n) if spread == "uniform" else rng.exponential(1.0, n)
    fn = mean_force * (1 + a_n * np.cos(2 * (theta - theta_0))) * factor
    ft = -mean_force * a_t * np.sin(2 * (theta - theta_0)) * np.ones(n)
    kind = np.where(rng.uniform(size=n) < double_fraction, 2, 1).astype("i1")
    return normal, fn, ft, kind


def harmonic_series(n_snapshots=10, n_contacts=1000, anisotropy=(0.3, 0.4, 0.25), theta_0=0.0,
                    seed=0, spread="exponential", double_fraction=0.3):
    """A dataset of ``n_snapshots`` snapshots of ``n_contacts`` isolated contact pairs.

    Particle 2k touches particle 2k+1 at distance 0.02 m along the drawn normal, so every
    contact is its own pair; the anisotropies grow linearly from 0 to ``anisotropy`` (a, a_n,
    a_t) over the series and the box shrinks in height and widens, like a biaxial test. The
    box, l x 2l, holds the particles at a solid fraction of :data:`SOLID_FRACTION` at the
    start (l at least 8 pair lengths), and every pair lies inside it, carried by the box's
    affine deformation.
    """
    rng = np.random.default_rng(seed)
    n_part = 2 * n_contacts
    i = np.arange(0, n_part, 2, dtype="i4")
    radius = PAIR_LENGTH_M / 2
    width = max(np.sqrt(n_part * np.pi * radius ** 2 / SOLID_FRACTION / 2), 8 * PAIR_LENGTH_M)
    strain = np.linspace(0, 0.1, n_snapshots)
    box_max = np.stack([width * (1 + 0.5 * strain), 2 * width * (1 - strain)], -1)
    margin = PAIR_LENGTH_M + radius  # the partner, one pair length away in any direction, stays inside
    where = rng.uniform(0, 1, (n_contacts, 2))
    pos = np.zeros((n_snapshots, n_part, 2))
    pos[:, i] = margin + where[None] * (box_max[:, None, :] - 2 * margin)
    contacts = []
    for k in range(n_snapshots):
        s = k / max(n_snapshots - 1, 1)
        a, a_n, a_t = (s * v for v in anisotropy)
        normal, fn, ft, kind = harmonic_contacts(n_contacts, a, a_n, a_t, theta_0, rng=rng,
                                                 spread=spread, double_fraction=double_fraction)
        pos[k, i + 1] = pos[k, i] + PAIR_LENGTH_M * normal
        contacts.append(dict(i=i, j=i + 1, kind=kind, normal=normal, fn=fn, ft=ft))
    return make_dataset(radius=np.full(n_part, radius), position=pos, contacts=contacts,
                        box_min=np.zeros((n_snapshots, 2)), box_max=box_max,
                        time=np.arange(n_snapshots, dtype=float), n_contact_slots=n_contacts,
                        # the function's former name, which files have always carried (and which still imports)
                        attrs={"source": "grainview.analysis.synthetic.harmonic_series", "seed": seed})
