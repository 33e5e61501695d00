"""A study's CSV: its columns and their types, the resumable rows, and reading it back.

``run_study`` (`pdw.studies.sweep`) appends one row per finished point and resumes from the rows
already there. The CSV is typed by its columns (``COLUMN_TYPES``): ``index`` and ``n_steps``
integers, the axes and the descriptors real numbers, ``status``, ``gait``, ``source``,
``error``, ``settings`` text; an empty cell is a value not computed. A row read back has the
types a computed row has, so a resumed row is written again as it was (``6`` stays ``6``,
issue 26.7: it became ``6.0``), and a row whose cell does not parse as its column's type, or
whose status, gait or source is not one pdw writes (a corrupt middle row) is dropped and its
point computed again, never reused.

`load_sweep(path)` (also `pdw.load` of a ``.csv``) reads a study's CSV in one call without
the `Study`: a pandas DataFrame when pandas is installed (``as_frame=None``, the default), else
a NumPy structured array with one field per column (``as_frame=False`` asks for it always;
``as_frame=True`` needs pandas and says so in one line if it is missing).
"""
from __future__ import annotations

import csv
import io
import math
import pathlib

import numpy as np

from ..core.errors import InvalidInputError, PdwError
from ..sim import files as _files
from .study import COLUMNS

#: The type of each fixed column (the axes, whose names vary, are float).
COLUMN_TYPES = {"index": int, "status": str, "gait": str, "source": str, "n_steps": int,
                "error": str, "settings": str}
COLUMN_TYPES.update({c: float for c in COLUMNS if c not in COLUMN_TYPES})
#: The values pdw writes in the text columns (the empty cell: not computed).
STATUSES = ("walked", "periodic", "fell", "diverged", "no_steps", "interrupted", "no_gait",
            "unstable", "error")
GAITS = ("", "period-1", "period-2", "none", "unstable")
SOURCES = ("", "simulate", "newton")


def header(study) -> list:
    return ["index"] + study.axis_names + list(COLUMNS)


def fmt(v) -> str:
    """A cell: floats by repr (exact), NaN as ``nan``, integers and text as they are."""
    if isinstance(v, (float, np.floating)):
        v = float(v)
        return repr(v) if math.isfinite(v) else ("nan" if math.isnan(v) else repr(v))
    return str(v)


def csv_line(row, columns) -> str:
    buf = io.StringIO()
    csv.writer(buf, lineterminator="\n").writerow([fmt(row.get(c, "")) for c in columns])
    return buf.getvalue()


class _Corrupt(ValueError):
    pass


def parse(column, text):
    """A cell of ``column`` in its type (``COLUMN_TYPES``; an axis: float); "" stays "" (not
    computed) except for ``index``. A cell that does not parse raises ValueError."""
    kind = COLUMN_TYPES.get(column, float)
    if kind is str:
        return text
    if text == "":
        if column == "index":
            raise _Corrupt("index is empty")
        return ""
    if kind is int:
        if not text.lstrip("-").isdigit():
            raise _Corrupt("%s = %r is not an integer" % (column, text))
        return int(text)
    try:
        return float(text)
    except ValueError:
        raise _Corrupt("%s = %r is not a number" % (column, text)) from None


def typed_row(columns, cells) -> dict:
    """The row of ``cells`` (text) with each column in its type; `ValueError` for a corrupt
    one (a cell that does not parse; a status, gait or source pdw does not write)."""
    if len(cells) != len(columns):
        raise _Corrupt("%d cells for %d columns" % (len(cells), len(columns)))
    row = {c: parse(c, v) for c, v in zip(columns, cells)}
    for name, allowed in (("status", STATUSES + ("",)), ("gait", GAITS), ("source", SOURCES)):
        if name in row and row[name] not in allowed:
            raise _Corrupt("%s = %r is not one pdw writes" % (name, row[name]))
    return row


def read_rows(path, study) -> dict:
    """Rows already in a study's CSV, by index, typed as computed rows are; checks that they
    belong to ``study`` (same columns, same axis values). Torn lines (a write cut by a kill),
    corrupt rows (a cell that does not parse as its column's type, an unknown status), rows
    computed under other settings (their ``settings`` hash differs: another preset, method,
    [run], fixed parameter or model) and ``error`` rows are dropped: they are computed again."""
    path = pathlib.Path(path)
    if not path.exists():
        return {}
    lines = path.read_text().splitlines()
    if not lines:
        return {}
    want = header(study)
    head = next(csv.reader([lines[0]]))
    if head != want:
        raise PdwError("%s: its columns %s are not this study's %s; use a fresh output folder "
                       "or resume=False (--fresh)" % (path, head, want))
    pts = dict(study.points())
    rows = {}
    for line in lines[1:]:
        rec = next(csv.reader([line]), None)
        if rec is None:
            continue
        try:
            row = typed_row(head, rec)
        except ValueError:
            continue                                   # torn or corrupt: computed again
        k = row["index"]
        if k not in pts or any(row[a] == "" or not np.isclose(row[a], pts[k][a], rtol=1e-12,
                                                                atol=0)
                               for a in study.axis_names):
            raise PdwError("%s: row %s does not match this study's point %s; use a fresh output "
                           "folder or resume=False (--fresh)" % (path, k, pts.get(k)))
        if row["status"] in ("", "error") or row["settings"] != study.task(k, pts[k])["settings"]:
            continue
        rows[k] = row
    return rows


def load_sweep(path, *, as_frame: bool | None = None):
    """A study's CSV (written by ``pdw sweep`` / ``run_study``) in one call, without the Study.

    Parameters
    ----------
    path : str or path-like
        The ``<name>.csv`` of a study's output folder.
    as_frame : bool or None
        None (default): a pandas DataFrame if pandas is installed, else a NumPy structured
        array; True: a DataFrame (pandas is then required: an ImportError says so in one
        line); False: the structured array.

    Returns
    -------
    pandas.DataFrame or numpy.ndarray
        One row per point, the columns of the CSV in their types (``COLUMN_TYPES``; the axes
        float): integers as int64 (an empty ``n_steps`` as -1 in the structured array, NA in
        the DataFrame), reals as float64 (empty: NaN), text as str. Torn lines are skipped;
        a corrupt row is `pdw.InvalidInputError` naming the file and the line.

    Raises
    ------
    pdw.InvalidInputError
        No such file, or not a study's CSV (its first column must be ``index``, and the
        descriptor columns of ``pdw.studies.study.COLUMNS`` must be there).
    """
    path = pathlib.Path(path)
    try:
        text = path.read_text()
    except FileNotFoundError:
        raise InvalidInputError("%s: no such file (pdw.load reads .npz or .nc files pdw wrote "
                                "and a sweep's .csv)" % path) from None
    except (OSError, UnicodeDecodeError) as e:
        raise InvalidInputError("%s is not a readable sweep CSV: %s: %s"
                                % (path, type(e).__name__, e)) from None
    lines = text.splitlines()
    head = next(csv.reader([lines[0]]), []) if lines else []
    if not head or head[0] != "index" or list(head[-len(COLUMNS):]) != list(COLUMNS):
        raise InvalidInputError("%s is not a pdw sweep CSV (its columns must be index, the "
                                "axes, then %s; got %s)" % (path, ", ".join(COLUMNS), head[:6]))
    rows = []
    for n, line in enumerate(lines[1:], start=2):
        rec = next(csv.reader([line]), None)
        if rec is None or len(rec) != len(head):
            continue                                   # a torn last line
        try:
            rows.append(typed_row(head, rec))
        except ValueError as e:
            raise InvalidInputError("%s, line %d: %s" % (path, n, e)) from None
    want_frame = as_frame
    if want_frame is None or want_frame:
        try:
            import pandas as pd
        except ImportError:
            if want_frame:
                raise ImportError("load_sweep(as_frame=True) needs pandas (pip install pandas)"
                                  ) from None
            want_frame = False
        else:
            want_frame = True
    kinds = {c: COLUMN_TYPES.get(c, float) for c in head}
    if want_frame:
        cols = {}
        for c in head:
            v = [r[c] for r in rows]
            if kinds[c] is float:
                cols[c] = pd.array([np.nan if x == "" else x for x in v], dtype="float64")
            elif kinds[c] is int:
                cols[c] = pd.array([None if x == "" else x for x in v], dtype="Int64")
            else:
                cols[c] = pd.array(v, dtype=object)
        df = pd.DataFrame(cols)
        df.attrs["path"] = str(path)
        return df
    dtype = [(c, "f8" if kinds[c] is float else "i8" if kinds[c] is int
              else "U%d" % max([1] + [len(r[c]) for r in rows])) for c in head]
    out = np.zeros(len(rows), dtype=dtype)
    for i, r in enumerate(rows):
        out[i] = tuple((np.nan if kinds[c] is float else -1) if r[c] == "" and kinds[c] is not str
                       else r[c] for c in head)
    return out


_files.register_suffix(".csv", load_sweep)
