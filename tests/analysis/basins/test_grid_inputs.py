"""Issue 26, items 1 and 7, in the analysis layer: the grid sizes of `cell_map` and `basin`.

A grid of ``(lo, hi, 2**62)`` cells gave a raw numpy ``ValueError`` ("array is too big"); a size
of 1.5 was read as 1 and a ``chunk_size`` of 2.5 as 2. Each axis is now (finite lo < hi, an
integer n in [1, MAX_GRID]) and ``chunk_size`` an integer, or `InvalidInputError` naming it.
"""
import pytest

import pdw
from pdw.analysis.basins import basin, cell_mapping

P = pdw.Params.paper_steady()
OK = (-2.0, -1.8, 2)


@pytest.mark.parametrize("phi,match", [
    ((0.74, 0.76, 2 ** 62), r"phi\[2\] \(n\)"), ((0.74, 0.76, 1.5), r"phi\[2\] \(n\)"),
    ((0.74, 0.76, True), r"phi\[2\] \(n\)"), ((0.74, 0.76, "3"), r"phi\[2\] \(n\)"),
    ((0.76, 0.74, 2), "lo < hi"), ((float("nan"), 0.76, 2), r"phi\[0\]"), ((0.7, 2), "phi"),
])
@pytest.mark.parametrize("fn", ["cell_map", "basin"])
def test_grid_axes_are_checked(fn, phi, match):
    with pytest.raises(pdw.InvalidInputError, match=match):
        if fn == "cell_map":
            cell_mapping.cell_map(P, phi=phi, thetad2=OK)
        else:
            basin.basin(P, phi=phi, thetad2=OK)


def test_basin_chunk_size_is_an_integer():
    with pytest.raises(pdw.InvalidInputError, match="chunk_size"):
        basin.basin(P, phi=(0.74, 0.76, 2), thetad2=OK, chunk_size=2.5)
