"""``grainview demo``: a synthetic series drawn from the harmonic model, written to a file and
analysed lazily from it, with no simulation (seconds).

The series (:func:`grainview.datasets.harmonic_series`) has contacts whose normal
density and mean forces follow Eqs. (6)-(8) of Azéma et al. (2007); q/p computed from the file
is compared with the harmonic prediction q/p = (a' + a_n + a_t)/2, Eq. (9), each column
computed with dask from a file opened in chunks of 5 snapshots.
"""

from __future__ import annotations

from pathlib import Path

from ..contract.errors import ParameterError

SNAPSHOTS = 11
"""Snapshots of the demo's series by default."""
CONTACTS = 20000
"""Contacts per snapshot of the demo's series by default: enough that reading it lazily matters."""


def run_demo(out, *, snapshots=SNAPSHOTS, contacts=CONTACTS, seed=None, overwrite=False, compress=True, log=None):
    """Write ``out/synthetic.nc`` (``snapshots`` snapshots of ``contacts`` contacts; large
    enough by default that reading it lazily matters) and ``out/harmonic_prediction.csv``.

    Parameters
    ----------
    out : path-like
        Output folder (made if needed).
    snapshots, contacts : int
        The series' size: at least 2 snapshots and 1 contact.
    seed : int, optional
        Random seed (default: the series' own).
    overwrite : bool
        Replace existing output files; otherwise either one existing is refused before
        anything is written.
    compress : bool
        Write the file compressed (zlib).
    log : callable, optional
        Called with one line saying where the two files go, once they are known not to
        replace anything (or ``overwrite`` allows it).

    Returns
    -------
    (pathlib.Path, pandas.DataFrame)
        The file, and per snapshot q/p, the prediction (a' + a_n + a_t)/2, a', a_n, a_t (1).

    Raises
    ------
    grainview.contract.errors.ParameterError
        For fewer than 2 snapshots or 1 contact.
    FileExistsError
        When an output file exists and ``overwrite`` is False.
    """
    from ..datasets import harmonic_series
    from ..contract.dataset import netcdf_options
    from ..formats.opening import open_dataset

    if snapshots < 2 or contacts < 1:
        raise ParameterError(f"snapshots={snapshots}, contacts={contacts}: expected at least 2 snapshots and 1 "
                             "contact")
    path, csv = demo_outputs(out)
    if not overwrite:
        for target in (path, csv):
            if target.exists():
                raise FileExistsError(f"{target} exists; pass overwrite=True to replace it")
    if log is not None:
        log(f"writing {path} and {csv} ...")
    path.parent.mkdir(parents=True, exist_ok=True)
    ds = harmonic_series(n_snapshots=snapshots, n_contacts=contacts, **({} if seed is None else {"seed": seed}))
    tmp = path.with_suffix(".nc.part")  # written whole, then renamed: never a half-written file
    ds.to_netcdf(tmp, **netcdf_options(ds, compress=compress))
    tmp.replace(path)
    lazy = open_dataset(path, chunks=5, validate=True)
    table = lazy.grain.harmonic_prediction().compute()
    table["a"] = lazy.grain.fabric_anisotropy()["a"].compute()
    frame = table.to_dataframe()[["q_over_p", "prediction", "a_prime", "a_n", "a_t"]]
    part = csv.with_suffix(".csv.part")
    frame.to_csv(part)
    part.replace(csv)
    return path, frame


def demo_outputs(out) -> tuple[Path, Path]:
    """The two files :func:`run_demo` writes into folder ``out``: the series and its table.

    Parameters
    ----------
    out : path-like
        The output folder.

    Returns
    -------
    (pathlib.Path, pathlib.Path)
        ``out/synthetic.nc`` and ``out/harmonic_prediction.csv``.
    """
    out = Path(out)
    return out / "synthetic.nc", out / "harmonic_prediction.csv"
