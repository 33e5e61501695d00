"""Issue 26, item 7: no silent coercion of masked arrays (`pdw.core.checks`).

``np.asarray`` drops a masked array's mask: `pdw.simulate` ran a masked x0 on the hidden values
under the mask. A masked array with any masked entry is now refused wherever pdw takes an array
or a number (states, flags, counts, parameters), naming the field; one with no masked entry is
its data.
"""
import numpy as np
import pytest

import pdw
from pdw.core import checks

X0 = np.array(pdw.X0_PAPER, dtype=float)


def _masked(i=1):
    mask = np.zeros(8, bool)
    mask[i] = True
    return np.ma.masked_array(X0.copy(), mask=mask)


CALLS = [
    ("simulate", lambda x: pdw.simulate(x, t_end=0.001)),
    ("simulate_batch", lambda x: pdw.simulate_batch(np.ma.vstack([x, x]), t_end=0.001)),
    ("rhs", lambda x: pdw.rhs(x)),
    ("jacobian", lambda x: pdw.jacobian(x)),
    ("contact_forces", lambda x: pdw.contact_forces(x)),
    ("energies", lambda x: pdw.energies(x)),
    ("mass_matrix", lambda x: pdw.mass_matrix(x)),
    ("Scene", lambda x: pdw.run(pdw.Scene(x0=x))),
]


@pytest.mark.parametrize("name,call", CALLS, ids=[c[0] for c in CALLS])
def test_a_masked_state_is_refused_naming_the_field(name, call):
    with pytest.raises(pdw.InvalidInputError, match="masked"):
        call(_masked())


def test_a_masked_array_without_masked_entries_is_its_data():
    x = np.ma.masked_array(X0.copy(), mask=np.zeros(8, bool))
    assert np.array_equal(pdw.rhs(x), pdw.rhs(X0))
    r1, r2 = pdw.simulate(x, t_end=0.01), pdw.simulate(X0, t_end=0.01)
    assert np.array_equal(r1.x, r2.x)


@pytest.mark.parametrize("check,args", [
    (checks.count, ("n", np.ma.masked_array([3], mask=[True])[0])),
    (checks.number, ("v", np.ma.masked_array(2.0, mask=True))),
    (checks.flags, ("flags", np.ma.masked_array([0, 1], mask=[False, True]))),
    (checks.real_array, ("x", np.ma.masked_array([1.0, 2.0], mask=[True, False]), [(2,)])),
])
def test_every_check_refuses_masked_entries(check, args):
    with pytest.raises(pdw.InvalidInputError):
        check(*args)


@pytest.mark.parametrize("bad", [1.5, True, "3", np.float64(2.5)])
def test_counts_accept_only_integral_values(bad):
    with pytest.raises(pdw.InvalidInputError, match="integer"):
        checks.count("n", bad)
    assert checks.count("n", 3.0) == 3 and checks.count("n", np.int64(3)) == 3
