"""Issue 26, items 7 and 10: a study's CSV (`pdw.studies.table`).

Item 7: a sweep resume re-typed ``n_steps`` ('6' became '6.0') and reused corrupt middle rows
(a cell that does not parse, an unknown status). The CSV is typed by its columns: a resumed row
is written back as it was, a corrupt row is computed again. Item 10: `pdw.load_sweep(path)` (and
`pdw.load` of the ``.csv``) reads it back in one call without the Study: a DataFrame with
pandas, a structured array without.
"""
import csv
import sys

import numpy as np
import pytest

import pdw
from pdw.studies import sweep, table

SPEC = """
name = "csvt"
[scene]
preset = "paper_steady"
stop = { t_end = 2.5 }
record = { every = 0 }
[[axes]]
name = "gamma"
values = [0.036, 0.04, 0.044]
[run]
steady = 2
fallback = false
"""


def _study():
    return sweep.parse_study(SPEC)


def _rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def test_a_resume_keeps_the_types_of_every_cell(tmp_path):
    st = _study()
    sweep.run_study(st, tmp_path, backend="serial")
    first = (tmp_path / "csvt.csv").read_text()
    assert any(r["n_steps"] and "." not in r["n_steps"] for r in _rows(tmp_path / "csvt.csv"))
    res = sweep.run_study(st, tmp_path, backend="serial")       # all resumed
    assert res.computed == [] and len(res.resumed) == 3
    assert (tmp_path / "csvt.csv").read_text() == first         # byte for byte
    for r in res.rows:
        assert isinstance(r["index"], int)
        assert r["n_steps"] == "" or type(r["n_steps"]) is int
        assert isinstance(r["gamma"], float) and isinstance(r["status"], str)


@pytest.mark.parametrize("column,junk", [("L", "abc"), ("n_steps", "6.5"), ("status", "walkedX"),
                                          ("t_final", "1.2.3"), ("gait", "period-7"),
                                          ("n_steps", "x")])
def test_a_corrupt_middle_row_is_computed_again(tmp_path, column, junk):
    st = _study()
    sweep.run_study(st, tmp_path, backend="serial")
    path = tmp_path / "csvt.csv"
    rows = _rows(path)
    good = rows[1][column]
    rows[1][column] = junk                                      # the middle row, corrupted
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]), lineterminator="\n")
        w.writeheader()
        w.writerows(rows)
    res = sweep.run_study(st, tmp_path, backend="serial")
    assert res.computed == [1] and res.resumed == [0, 2]
    assert _rows(path)[1][column] == good


def test_load_sweep_reads_the_csv_in_one_call(tmp_path):
    pd = pytest.importorskip("pandas")
    st = _study()
    res = sweep.run_study(st, tmp_path, backend="serial")
    df = pdw.load_sweep(tmp_path / "csvt.csv")
    assert isinstance(df, pd.DataFrame) and len(df) == 3
    assert list(df.columns) == table.header(st)
    assert str(df["n_steps"].dtype) == "Int64" and df["L"].dtype == np.float64
    assert df["gamma"].tolist() == [0.036, 0.04, 0.044]
    assert df["status"].tolist() == [r["status"] for r in res.rows]
    assert np.allclose(df["L"], res.column("L"), equal_nan=True)
    df2 = pdw.load(tmp_path / "csvt.csv")                       # pdw.load of the CSV
    assert df2.equals(df)


def test_load_sweep_without_pandas_gives_a_structured_array(tmp_path, monkeypatch):
    st = _study()
    res = sweep.run_study(st, tmp_path, backend="serial")
    a = pdw.load_sweep(tmp_path / "csvt.csv", as_frame=False)
    assert a.dtype.names == tuple(table.header(st)) and len(a) == 3
    assert a["index"].tolist() == [0, 1, 2] and a["n_steps"].dtype == np.int64
    assert np.allclose(a["L"], res.column("L"), equal_nan=True)
    monkeypatch.setitem(sys.modules, "pandas", None)            # pandas not installed
    b = pdw.load_sweep(tmp_path / "csvt.csv")
    assert isinstance(b, np.ndarray) and b.dtype == a.dtype
    assert all(np.array_equal(b[n], a[n], equal_nan=b[n].dtype.kind == "f") for n in a.dtype.names)
    with pytest.raises(ImportError, match="pip install pandas"):
        pdw.load_sweep(tmp_path / "csvt.csv", as_frame=True)


def test_load_sweep_refuses_what_is_not_a_sweep_csv(tmp_path):
    with pytest.raises(pdw.InvalidInputError, match="no such file"):
        pdw.load_sweep(tmp_path / "none.csv")
    p = tmp_path / "other.csv"
    p.write_text("a,b\n1,2\n")
    with pytest.raises(pdw.InvalidInputError, match="not a pdw sweep CSV"):
        pdw.load(p)
    st = _study()
    sweep.run_study(st, tmp_path, backend="serial")
    text = (tmp_path / "csvt.csv").read_text().splitlines()
    cells = text[2].split(",")
    cells[-3] = "zz"                                           # wall_s
    text[2] = ",".join(cells)
    (tmp_path / "bad.csv").write_text("\n".join(text) + "\n")
    with pytest.raises(pdw.InvalidInputError, match=r"bad.csv, line 3"):
        pdw.load_sweep(tmp_path / "bad.csv")
