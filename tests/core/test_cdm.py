"""The paper's central difference method against its equations (docs/model.md section 7, Eqs.
13-17), computed independently here in NumPy.

M(q) comes from `pdw.mass_matrix`, C(q, qd) is typed in from docs/model.md section 3, and
Q_f - G = M qdd + C qd with qdd from `pdw.rhs` (Eq. A.4 solved for Q_f - G): none of it goes
through the compiled cdm loop (pdw_cdm.c). Then

    start:    U_-1 = U_0 - dt U'_0 + dt^2/2 U''_0                                 (Eq. 13)
    step:     (M/dt^2 + C/2dt) U_n+1 = Q_f - G + 2/dt^2 M U_n - (M/dt^2 - C/2dt) U_n-1   (14-16)
    velocity: U'_n+1 = (U_n+1 - U_n-1) / (2 dt)                                  (Eq. 17)

must give the recorded states of `pdw.simulate(method="cdm")`. Tolerances: 1e-12 m or rad on
U (a step changes U by ~1e-4), 1e-8 on U' (the differences of Eq. 17 amplify the rounding of U
by 1/(2 dt) = 5e3); a start-up term changed by a factor of two moves U_1 by dt^2 |U''| / 4,
about 1e-7 here.
"""
import numpy as np
import pytest

import pdw

DT = 1e-4


def _C(q, qd, p):
    """docs/model.md section 3's C(q, qd), typed in (only its first two rows are non-zero)."""
    s1, c1, s2, c2 = np.sin(q[2]), np.cos(q[2]), np.sin(q[3]), np.cos(q[3])
    C = np.zeros((4, 4))
    C[0, 2] = -p.m_l * (p.c * s1 + p.w * c1) * qd[2]
    C[0, 3] = -p.m_l * (p.c * s2 + p.w * c2) * qd[3]
    C[1, 2] = p.m_l * (p.c * c1 - p.w * s1) * qd[2]
    C[1, 3] = p.m_l * (p.c * c2 - p.w * s2) * qd[3]
    return C


def _terms(x, p, flags, anchors, variant):
    """M, C and Q_f - G at state x = [U_n, U'_n]."""
    q, qd = x[:4], x[4:]
    M = pdw.mass_matrix(q, p)
    C = _C(q, qd, p)
    qdd = pdw.rhs(x, p, flags=flags, anchors=anchors, variant=variant)[4:]
    return M, C, M @ qdd + C @ qd


def _step(x, u_prev, p, flags, anchors, variant, dt=DT):
    """Eqs. 14-17: (U_n+1, U'_n+1) from x = [U_n, U'_n] and U_n-1."""
    M, C, QmG = _terms(x, p, flags, anchors, variant)
    K = M / dt**2 + C / (2 * dt)
    b = QmG + 2 / dt**2 * M @ x[:4] - (M / dt**2 - C / (2 * dt)) @ u_prev
    u = np.linalg.solve(K, b)
    return u, (u - u_prev) / (2 * dt)


def _start(x0, p, flags, anchors, variant, dt=DT):
    """Eq. 13: U_-1."""
    qdd = pdw.rhs(x0, p, flags=flags, anchors=anchors, variant=variant)[4:]
    return x0[:4] - dt * x0[4:] + 0.5 * dt**2 * qdd


def _close(got, q, qd, what):
    np.testing.assert_allclose(got[:4], q, rtol=0, atol=1e-12, err_msg=what + ": U")
    np.testing.assert_allclose(got[4:], qd, rtol=0, atol=1e-8, err_msg=what + ": U'")


def test_C_typed_in_gives_the_models_velocity_terms():
    """The typed-in C of section 3 is the model's: M qdd + C qd + G - Q_f = 0 needs C qd;
    with the contact forces off (feet in the air) and no hip spring or damper, Q_f - G is
    the gravity term alone, which does not depend on qd: so M qdd + C qd is the same for two
    states with the same q and different qd."""
    p = pdw.Params.paper(k_hip=0.0, d_hip=0.0)
    x = np.array(pdw.X0_PAPER, float)
    x[1] += 0.05                                    # both feet 5 cm up: no contact
    x2 = x.copy()
    x2[4:] = [0.3, -0.2, 1.5, -2.0]
    qmg = [_terms(z, p, (0, 0), (0.0, 0.0), "paper")[2] for z in (x, x2)]
    np.testing.assert_allclose(qmg[0], qmg[1], rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("variant", pdw.VARIANTS)
@pytest.mark.parametrize("x0", [pdw.X0_PAPER, pdw.X0_DISTURBED], ids=["paper", "disturbed"])
def test_first_steps_follow_eqs_13_to_17(variant, x0):
    """The start-up (Eq. 13) and the first two updates from flags0 = (0, 1) (leg 2 anchored at
    x0; the disturbed start lifts it off at t = 0, as the flags recorded at step 0 say)."""
    p = pdw.Params.paper()
    x0 = np.asarray(x0, float)
    anchors = (0.0, float(pdw.contact_forces(x0, p, variant=variant).s[1]))
    r = pdw.simulate(x0, t_end=2 * DT, dt=DT, variant=variant,
                     integrator=pdw.Integrator(check_step="off"), record=pdw.Record(every=1))
    flags = tuple(int(f) for f in r.flags[0])
    assert tuple(r.flags[1]) == tuple(r.flags[2]) == flags
    u_m1 = _start(x0, p, flags, anchors, variant)
    u1, v1 = _step(x0, u_m1, p, flags, anchors, variant)
    _close(r.x[1], u1, v1, "step 1")
    u2, v2 = _step(r.x[1], x0[:4], p, flags, anchors, variant)
    _close(r.x[2], u2, v2, "step 2")
    # not vacuous: the start-up's half changes U_1 by far more than the tolerance
    qdd = pdw.rhs(x0, p, flags=flags, anchors=anchors, variant=variant)[4:]
    assert np.max(np.abs(0.25 * DT**2 * qdd)) > 1e-9


def test_steps_of_a_walk_follow_eqs_14_to_17():
    """Every 250th step of a 3 s walk (swing, double support, impacts; paper variant, whose
    forces do not depend on the anchors): U_n+1 and U'_n+1 from the recorded U_n-1, U_n, U'_n
    and the recorded flags of step n."""
    p = pdw.Params.paper()
    r = pdw.simulate(t_end=3.0, dt=DT, integrator=pdw.Integrator(check_step="off"),
                     record=pdw.Record(every=1))
    assert r.status == "walked" and len(r.events) >= 8
    flags_seen = set()
    for n in range(1, len(r.t) - 1, 250):
        flags = tuple(int(f) for f in r.flags[n])
        flags_seen.add(flags)
        u, v = _step(r.x[n], r.x[n - 1][:4], p, flags, (0.0, 0.0), "paper")
        _close(r.x[n + 1], u, v, "step %d" % n)
    assert flags_seen >= {(0, 1), (1, 0)}, flags_seen


def test_velocity_is_eq_17_as_printed():
    """Eq. 17 as printed: the centred difference of the positions two steps apart, not the
    backward difference of the last step (the two differ by ~dt/2 |U''|)."""
    r = pdw.simulate(t_end=0.05, dt=DT, integrator=pdw.Integrator(check_step="off"),
                     record=pdw.Record(every=1))
    U = r.x[:, :4]
    centred = (U[2:] - U[:-2]) / (2 * DT)
    np.testing.assert_allclose(r.x[2:, 4:], centred, rtol=0, atol=1e-8)
    backward = (U[2:] - U[1:-1]) / DT
    assert np.max(np.abs(backward - centred)) > 1e-4
