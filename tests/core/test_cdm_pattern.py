"""The structural zeros of the central difference matrices, as derive/ emits them.

`pdw.core._layout.CDM_M_NZ` / `CDM_C_NZ` (and `PDW_CDM_M_NZ` / `PDW_CDM_C_NZ` in
generated/pdw_model.h, which the compiled update pdw_cdm.c reads) mark the entries (i, j) of M and
of the appendix C matrix that are not identically zero (bit 4 i + j). The update skips the others,
so the pattern must be exact: every entry outside it is 0 at every state of every kernel, and
every entry inside it is non-zero at some state (a pattern that marked a zero entry would still be
correct, but would not be the structural pattern the issue asks for; one that missed a non-zero
entry would silently drop a term of Eq. 14).
"""
import numpy as np
import pytest

from pdw.core import _core, _layout

NQ = _layout.NQ
KERNELS = range(len(_layout.KERNELS))


def _mask(bits):
    return np.array([(bits >> k) & 1 for k in range(NQ * NQ)], dtype=bool)


def _terms(k, rng):
    x = np.zeros(len(_layout.STATE))
    x[:] = rng.uniform(-1.0, 1.0, x.size)
    p = rng.uniform(0.1, 2.0, len(_layout.PARAMS) + len(_layout.DERIVED)
                    + len(_layout.CONTACT_PARAMS))
    contact = rng.uniform(-50.0, 50.0, 2 * len(_layout.CONTACT))
    M, C, QmG = np.empty(NQ * NQ), np.empty(NQ * NQ), np.empty(NQ)
    _core.cdm_terms(k, x, p, contact, M, C, QmG)
    return M, C


@pytest.mark.parametrize("k", KERNELS, ids=[name for name, *_ in _layout.KERNELS])
def test_entries_outside_the_emitted_pattern_are_zero_and_inside_it_are_not(k):
    rng = np.random.default_rng(k)
    m_nz, c_nz = _mask(_layout.CDM_M_NZ), _mask(_layout.CDM_C_NZ)
    seen_m, seen_c = np.zeros(NQ * NQ, bool), np.zeros(NQ * NQ, bool)
    for _ in range(20):
        M, C = _terms(k, rng)
        assert np.all(M[~m_nz] == 0.0), "M has a non-zero outside PDW_CDM_M_NZ"
        assert np.all(C[~c_nz] == 0.0), "C has a non-zero outside PDW_CDM_C_NZ"
        seen_m |= M != 0.0
        seen_c |= C != 0.0
    assert np.array_equal(seen_m, m_nz), "an entry marked in PDW_CDM_M_NZ was zero at every state"
    assert np.array_equal(seen_c, c_nz), "an entry marked in PDW_CDM_C_NZ was zero at every state"


def test_the_pattern_keeps_the_block_structure_the_solver_needs():
    """pdw_solve_dblock needs K's lower-right 2x2 block diagonal (pdw_cdm.c checks it when
    compiling); and C has the 4 non-zeros of docs/model.md section 3."""
    nz = _mask(_layout.CDM_M_NZ | _layout.CDM_C_NZ).reshape(NQ, NQ)
    assert not nz[2, 3] and not nz[3, 2] and nz[2, 2] and nz[3, 3]
    assert int(_mask(_layout.CDM_C_NZ).sum()) == 4
