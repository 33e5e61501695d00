"""The step-size check's limits of the presets, precomputed: the first fixed-step `simulate` of
a process looks them up instead of computing them (`pdw.sim.stepsize`; issue 23)."""
from __future__ import annotations

import functools

from ..core.params import Params

#: `pdw.sim.stepsize._dt_max` of the presets (`Params.paper`, `Params.paper_steady`), as
#: computed by `pdw.sim.stepsize._dt_max_computed` (about 7 ms each, which the first fixed-step
#: `simulate` of a process would pay: 2-3x the paper run it checks). tests/sim/test_speed.py checks
#: that every entry is still what the computation gives, bit for bit;
#: `pdw.sim.stepsize._preset_table()` computes the table anew.
PRESET_DT_MAX = {
    ("paper", "paper"): {"cdm": 0.0009030974043457654, "verlet": 0.000885461827847902,
                         "rk4": 0.0038950736442615094},
    ("paper", "consistent"): {"cdm": 0.0013552465686015552, "verlet": 0.0006777378803506724,
                              "rk4": 0.0027709840482022952},
    ("paper_steady", "paper"): {"cdm": 0.0009047607891374658, "verlet": 0.000885846897839419,
                                "rk4": 0.0038956723965252087},
    ("paper_steady", "consistent"): {"cdm": 0.0013597924412892721,
                                     "verlet": 0.0006781025277612672,
                                     "rk4": 0.0027724749375081332},
}


@functools.lru_cache(maxsize=1)
def _presets() -> dict:
    return {(getattr(Params, preset)(), variant): v
            for (preset, variant), v in PRESET_DT_MAX.items()}


def preset_limits(params: Params, variant: str) -> dict | None:
    """{method: dt_max} of ``params`` and ``variant`` when ``params`` is a preset, else None."""
    return _presets().get((params, variant))
