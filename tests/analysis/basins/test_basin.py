"""The classification of basin cells (`pdw.analysis.basins.basin`, docs/ensemble.md): a walker that
became periodic is the reference gait only when its last step length AND period are each within
``match_tol`` (relative) of the reference's; a periodic walker that misses either is another
gait; one still walking is undecided; a fall is a fall."""
import numpy as np

from pdw.analysis.basins import basin
from pdw.core import _layout

L0, P0, TOL = 0.37, 0.56, 0.02


def _batch(rows):
    """A stand-in for a BatchResult with what `_classify` reads: per walker (status, L, P,
    number of gait steps)."""
    n = len(rows)
    g = np.full((n, _layout.STEP_RING, len(_layout.STEP)), np.nan)
    iL, iP = _layout.STEP.index("L"), _layout.STEP.index("P")
    steps = np.array([r[3] for r in rows])
    for w, (_, L, P, k) in enumerate(rows):
        last = min(k, _layout.STEP_RING) - 1
        if k:
            g[w, :last + 1, iL] = L * 1.5          # earlier steps: far from the gait
            g[w, :last + 1, iP] = P * 1.5
            g[w, last, iL], g[w, last, iP] = L, P
    status = np.array([r[0] for r in rows])
    return _Batch(status, np.isin(status, ["walked", "periodic"]), g, steps)


class _Batch:
    def __init__(self, status, walked, gait_rows, n_gait_steps):
        self.status, self.walked = status, walked
        self.gait_rows, self.n_gait_steps = gait_rows, n_gait_steps

    def __len__(self):
        return len(self.status)


def test_gait_needs_both_step_length_and_period():
    near, far = 1 + 0.5 * TOL, 1 + 2 * TOL
    rows = [("periodic", L0 * near, P0 / near, 6),      # both within tol: the gait
            ("periodic", L0 * far, P0, 6),              # L off
            ("periodic", L0, P0 * far, 6),              # P off
            ("periodic", L0 / far, P0 / far, 40),       # both off (a ring that wrapped)
            ("periodic", L0, P0, 40),                   # the gait, ring wrapped
            ("walked", L0, P0, 8),                      # the gait's numbers, not periodic yet
            ("fell", L0, P0, 3)]
    out = basin._classify(_batch(rows), L0, P0, TOL)
    np.testing.assert_array_equal(out, [basin.GAIT, basin.OTHER, basin.OTHER, basin.OTHER,
                                        basin.GAIT, basin.UNDECIDED, basin.FELL])
