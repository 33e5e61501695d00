"""Layer 3 -- analyses of gaits, built on one simulation (docs/architecture.md).

gait_types      `Gait`, `GaitNotFoundError`: a periodic gait, the type every subpackage shares
stepmap/        the one-step (touch-down Poincare) map of the continuous walker: its section,
                one map, many maps, Newton's gaits (`find_gait`), the exact Jacobian, the
                step maps of one parameter that continuation follows
rigid/          the rigid-ground (hybrid impact-momentum) walker, its gaits and its chaos
bifurcation/    continuation of gaits and their bifurcations in one and two parameters
basins/         basins of attraction: cell mapping and point mapping of the touch-down map
robust/         robustness on ground that is not uniform: max step, GSN, first passage, Markov
numerics/       the numerics of the compliant contact: stability maps, drop-test calibration

Imports only from `pdw.sim` and `pdw.core`. The flat module paths of before the subpackages
(``from pdw.analysis import limit_cycle``, ...) still import for one release, with a
DeprecationWarning (`pdw.analysis._moved`).
"""
from . import _moved

_moved.install()


def __getattr__(name):
    """``pdw.analysis.<old flat module>``: the module at its new path (DeprecationWarning)."""
    return _moved.attribute(name)
