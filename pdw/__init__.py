"""pdw: the flexible planar passive walker on compliant ground (JMST 2018).

The package is built in layers, each importing only from the ones below it
(docs/architecture.md): `pdw.core` (compiled model) -> `pdw.sim` (one simulation) ->
`pdw.analysis` (gaits) -> `pdw.studies` (studies at scale) -> `pdw.present` (plots, reports,
CLI). This module is the curated public API.

Public API
----------
Params                  model parameters and presets (docs/model.md section 1)
rhs, jacobian           f(x) of Eq. A.4 and its Jacobian, compiled from the symbolic derivation
ode_function            f(t, x) and jac(t, x) for external solvers (solve_ivp), validated once
mass_matrix             M(q) of Eq. 2
contact_forces          contact kinematics and forces of both feet (Eqs. 3-11)
energies                kinetic and potential energies
simulate, Result        one compiled simulation (support flags, events, status)
Integrator, Record,     the options of a run, each named once (pdw.sim.options): how it is
Stop, Limits            integrated, what it records, when it stops, when it fell or diverged;
                        taken by simulate, simulate_batch, simulate_many and Scene alike
Outcome                 how a run ended (Result.outcome; status and stop_reason derive from it)
simulate_batch          N walkers in one call, W lanes in lockstep (docs/ensemble.md): BatchResult
simulate_many           N walkers: the batch engine when it runs the method, else pdw.simulate
Contact                 the normal and friction contact laws of a run (docs/contact_laws.md)
Ground, Patch           the ground as data: shape h(s) and contact patches (docs/terrain.md)
Scene, run              everything a simulation needs, as one object or TOML file (docs/scenes.md)
steps                   per-step gait descriptors (docs/model.md section 8)
hybrid                  the rigid-ground impact-momentum model (docs/model.md section 9): find_gait, ...
find_gait               period-one gait of the continuous model: Newton shooting on the touch-down
                        Poincare map, Floquet multipliers (pdw.limit_cycle; cell mapping:
                        pdw.cell_mapping)
continue_gait, Branch   continuation of gaits in one parameter: branches, Floquet multipliers,
                        folds, period doublings, Neimark-Sacker, ends (pdw.analysis.bifurcation.continuation;
                        ``pdw continue``); Branch.save / pdw.load
plot_branches, plot_curves   bifurcation diagrams (units on both axes, AUTO labels) and
                        two-parameter curves (pdw.present.plots_continuation)
continue_bifurcation    folds and period doublings followed in a second parameter (minimally
                        augmented; pdw.analysis.bifurcation.codim2): a BifurcationCurve
sweep                   parameter studies from TOML files: run_study, load_study (``pdw sweep``)
examples                the scenes and studies shipped with pdw (``pdw run --list-examples``)
Progress                the progress bar of long jobs (``progress=`` of sweeps, cell maps, basins,
                        continuation, figures; tqdm when installed, quiet off a terminal)
PdwError, SimulationError, DivergedError, InvalidInputError   the error hierarchy
GaitNotFoundError       no periodic gait from any starting guess (find_gait, continue_gait)
STATE, VARIANTS         the state layout and the contact variants (docs/model.md section 6)
"""
import sys as _sys

from . import examples  # package data: the shipped scenes and studies
from .analysis.basins import cell_mapping
from .analysis.bifurcation.branch import Bifurcation, Branch
from .analysis.bifurcation.codim2 import BifurcationCurve, continue_bifurcation
from .analysis.bifurcation.continuation import continue_gait
from .analysis.gait_types import Gait, GaitNotFoundError
from .analysis.rigid import hybrid
from .analysis.robust.first_passage import FirstPassage, first_passage
from .analysis.robust.markov import MarkovChain, markov_chain
from .analysis.robust.robustness import GaitSensitivity, MaxStep, gait_sensitivity, max_step
from .analysis.stepmap import limit_cycle
from .analysis.stepmap.limit_cycle import find_gait
from .core import __version__  # noqa: F401 (pdw.__version__)
from .core._layout import INPUT_HASH
from .core.contact import Contact
from .core.errors import (
    DivergedError,
    FellError,
    InvalidInputError,
    PdwDeprecationWarning,
    PdwError,
    SimulationError,
    SingularSystemError,
    StepSizeError,
    StepSizeWarning,
)
from .core.ground import Ground, Patch
from .core.integrators import METHODS
from .core.model import (
    STATE,
    VARIANTS,
    ContactState,
    contact_forces,
    energies,
    jacobian,
    mass_matrix,
    rhs,
)
from .core.ode import OdeFunction, ode_function
from .core.params import X0_DISTURBED, X0_PAPER, Params
from .core.progress import Progress
from .present.plots_continuation import plot_branches, plot_curves
from .sim import scene
from .sim.batch import BatchResult, simulate_batch
from .sim.buffers import RecordBuffer
from .sim.ensemble import simulate_many
from .sim.files import load
from .sim.gait import Steps, steps
from .sim.options import Integrator, Limits, Outcome, Record, Stop
from .sim.scene import Scene, run
from .sim.simulation import Event, Result, simulate
from .studies import sweep
from .studies.table import load_sweep

# The public modules of __all__ keep their flat import paths (``import pdw.hybrid``,
# ``from pdw.sweep import run_study``) from before the layers.
for _name, _module in (("scene", scene), ("hybrid", hybrid), ("limit_cycle", limit_cycle),
                       ("cell_mapping", cell_mapping), ("sweep", sweep)):
    _sys.modules[__name__ + "." + _name] = _module
del _name, _module

__all__ = [
    "Params", "rhs", "jacobian", "mass_matrix", "contact_forces", "ContactState", "energies",
    "STATE", "VARIANTS", "INPUT_HASH", "simulate", "Result", "simulate_batch", "simulate_many", "BatchResult",
    "Event", "METHODS", "X0_PAPER",
    "X0_DISTURBED", "steps", "Steps", "PdwError", "SimulationError", "DivergedError",
    "SingularSystemError", "FellError", "InvalidInputError", "hybrid", "Gait", "Scene", "run",
    "limit_cycle", "cell_mapping", "find_gait", "sweep",
    "StepSizeWarning", "StepSizeError", "PdwDeprecationWarning", "examples", "continue_gait", "Branch", "Bifurcation",
    "continue_bifurcation", "BifurcationCurve", "plot_branches", "plot_curves",
    "ode_function", "OdeFunction", "load", "load_sweep", "RecordBuffer",
    "Contact", "Progress", "GaitNotFoundError", "Integrator", "Record", "Stop", "Limits",
    "Outcome", "Ground", "Patch",
    "max_step", "MaxStep", "gait_sensitivity", "GaitSensitivity", "first_passage",
    "FirstPassage", "markov_chain", "MarkovChain",
]
