"""pdw: the flexible planar passive walker on compliant ground (JMST 2018).

Public API
----------
Params                  model parameters and presets (MODEL.md section 1)
rhs, jacobian           f(x) of Eq. A.4 and its Jacobian, compiled from the symbolic derivation
mass_matrix             M(q) of Eq. 2
contact_forces          contact kinematics and forces of both feet (Eqs. 3-11)
energies                kinetic and potential energies
simulate, Result        one compiled simulation (support flags, events, status)
Contact                 the normal and friction contact laws of a run (docs/contact_laws.md)
Scene, run              everything a simulation needs, as one object or TOML file (docs/scenes.md)
steps                   per-step gait descriptors (MODEL.md section 8)
hybrid                  the rigid-ground impact-momentum model (MODEL.md section 9): find_gait, ...
find_gait               period-one gait of the continuous model: Newton shooting on the touch-down
                        Poincare map, Floquet multipliers (pdw.limit_cycle; cell mapping:
                        pdw.cell_mapping)
sweep                   parameter studies from TOML files: run_study, load_study (``pdw sweep``)
PdwError, SimulationError, DivergedError, InvalidInputError   the error hierarchy
STATE, VARIANTS         the state layout and the contact variants (MODEL.md section 6)
"""
from ._layout import INPUT_HASH
from .model import (STATE, VARIANTS, ContactState, contact_forces, energies, jacobian,
                    mass_matrix, rhs)
from .errors import (DivergedError, FellError, InvalidInputError, PdwError, SimulationError,
                     SingularSystemError, StepSizeError, StepSizeWarning)
from .gait import Steps, steps
from .params import Params
from .contact import Contact
from . import hybrid
from .gait_types import Gait
from .simulation import METHODS, X0_DISTURBED, X0_PAPER, Event, Result, simulate
from . import scene
from .scene import Scene, run
from . import limit_cycle, cell_mapping, sweep
from .limit_cycle import find_gait

__version__ = "0.1.0"

__all__ = [
    "Params", "rhs", "jacobian", "mass_matrix", "contact_forces", "ContactState", "energies",
    "STATE", "VARIANTS", "INPUT_HASH", "simulate", "Result", "Event", "METHODS", "X0_PAPER",
    "X0_DISTURBED", "steps", "Steps", "PdwError", "SimulationError", "DivergedError",
    "SingularSystemError", "FellError", "InvalidInputError", "hybrid", "Gait", "Scene", "run",
    "limit_cycle", "cell_mapping", "find_gait", "sweep",
    "StepSizeWarning", "StepSizeError", "Contact",
]
