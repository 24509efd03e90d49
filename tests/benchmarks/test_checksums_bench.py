"""benchmarks/checksums.py compares what it says it compares: the same series compressed with
Fletcher-32 checksums on every variable and without any, the same values in both, and a
results table with one row per read."""

import numpy as np
import pytest

from .conftest import load_benchmark as load


@pytest.fixture(scope="module")
def result(tmp_path_factory):
    bench = load("checksums")
    from benchmarks.analysis import write_series

    folder = tmp_path_factory.mktemp("checksums")
    source = str(folder / "series.nc")
    write_series(source, 3, 500)
    return bench, bench.measure(source, 1, str(folder)), folder


def test_the_two_files_differ_by_their_checksums_only(result):
    import netCDF4

    bench, measured, folder = result
    assert measured["filters"]["with checksums"].startswith("20 of 20 variables with a checksum")
    assert measured["filters"]["without"].startswith("0 of 20 variables with a checksum")
    deflated = [text.split("deflated: ")[1] for text in measured["filters"].values()]
    assert deflated[0] == deflated[1]  # the same variables deflated in both
    extra = measured["sizes"]["with checksums"] - measured["sizes"]["without"]
    with netCDF4.Dataset(folder / "with.nc") as a, netCDF4.Dataset(folder / "without.nc") as b:
        assert 0 < extra < 200 * len(a.variables)  # a filter message per variable and 4 bytes per chunk
        for name in a.variables:
            np.testing.assert_array_equal(a.variables[name][...], b.variables[name][...], err_msg=name)


def test_the_table_has_a_row_per_read_and_the_rounds_ratios(result):
    bench, measured, _ = result
    text = bench.table("tiny", measured, 1)
    rows = [line for line in text.splitlines() if line.startswith("| ") and not line.startswith("| read")
            and not line.startswith("| file")]
    assert [row.split(" | ")[0][2:] for row in rows] == ["with checksums", "without", *bench.CASES]
    for case in bench.CASES:
        (ratio,) = measured["ratios"][case]
        a, b = measured["median"]["with checksums", case], measured["median"]["without", case]
        assert ratio == pytest.approx(a / b)
