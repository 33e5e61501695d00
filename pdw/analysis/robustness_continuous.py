"""The robustness measures for the continuous (compliant) model: a step or rough ground as a
`pdw.Ground` under `pdw.simulate_batch` (docs/robustness.md). Needs the Ground of issue 22
items 1, 2 and 7 (the terrain work); until it is in this tree every entry point says so."""
from __future__ import annotations

from ..core.errors import InvalidInputError

_NEEDS = ("model='continuous' needs pdw.Ground and per-walker grounds in simulate_batch "
          "(issue 22 items 1, 2, 7), which this build does not have yet; use model='hybrid'")


def step_trials_fn(params, **kw):
    raise InvalidInputError("max_step: " + _NEEDS)


def gait_sensitivity(params, names, **kw):
    raise InvalidInputError("gait_sensitivity: " + _NEEDS)


def first_passage(params, **kw):
    raise InvalidInputError("first_passage: " + _NEEDS)
