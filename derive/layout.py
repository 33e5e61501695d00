"""The one source of truth for every array layout shared by C and Python.

Each layout is an ordered tuple of field names; `derive.emit` turns them into C
``enum`` constants (``PDW_X_THETA1`` ...) in ``generated/pdw_model.h`` and into
the Python module ``pdw/core/_layout.py``. No other file may hard-code an index.
"""

# State x = [q, qdot] (paper Eq. 1), slope frame: X downhill along the slope, Y normal, up.
STATE = ("x_o", "y_o", "theta1", "theta2", "xd_o", "yd_o", "thetad1", "thetad2")
NQ = 4
# The LuGre friction law (derive/contact_laws.py) adds one bristle deflection per foot [m] to the
# continuous state, after the mechanical state. The state layout of each friction law:
BRISTLE = ("z1", "z2")
STATE_LAYOUTS = {
    "coulomb": STATE,               # the paper's smooth Coulomb law (Eq. 10): x = [q, qd]
    "lugre": STATE + BRISTLE,       # LuGre: x = [q, qd, z]
}
NX_MAX = max(len(s) for s in STATE_LAYOUTS.values())

# Physical parameters (paper Tables 1-3, docs/model.md section 1), in this order.
PARAMS = (
    "l", "c", "w", "r", "J_l", "m_h", "m_l", "k_hip", "d_hip", "gamma", "g",
    "k_n", "d_n", "k_t", "d_t", "v_s", "v_d", "mu_s", "mu_d",
)
# Derived constants appended to the parameter vector once per simulation
# (`pdw_precompute`), so that no kernel evaluates a transcendental of a parameter.
DERIVED = ("sin_gamma", "cos_gamma")
# Parameters of the contact laws beyond the paper's (derive/contact_laws.py, docs/contact_laws.md),
# appended after DERIVED: they are not `pdw.Params` fields but set from a `pdw.Contact`
# (zero unless a law that uses them is selected).
CONTACT_PARAMS = (
    "e_n",        # coefficient of restitution of the Lankarani-Nikravesh and Flores laws [-]
    "v_in_min",   # smallest approach speed those laws divide by [m/s]
    "sigma0",     # LuGre bristle stiffness per unit normal force [1/m]
    "sigma1",     # LuGre bristle damping per unit normal force [s/m]
    "sigma2",     # LuGre viscous friction per unit normal force [s/m]
    "lg_mu_s",    # LuGre static friction coefficient (Stribeck curve at v = 0) [-]
    "lg_mu_c",    # LuGre Coulomb friction coefficient (Stribeck curve for |v| >> v_s) [-]
    "lg_v_s",     # LuGre Stribeck velocity [m/s]
)

# Discrete per-foot values captured at touch-down, passed to the kinematics stage ("anchors"):
# the rolling coordinate s_i (the consistent variant's xi) and the approach speed -v_y (the
# Lankarani-Nikravesh and Flores damping), foot-major within each kind.
ANCHORS = ("s0_1", "s0_2", "v_in1", "v_in2")

# Per-foot contact kinematics (docs/model.md section 2, Eqs. 4, 5, 8, 9), for the kernel's variant.
KIN = (
    "x_D",    # contact point, along the slope [m] (Eq. 4)
    "y_D",    # contact point height above the slope [m]; depth delta = -y_D (Eq. 4)
    "v_x",    # slip velocity of the foot's material point [m/s] (Eq. 9)
    "v_y",    # normal rate of the variant [m/s] (Eq. 5); delta_dot = -v_y
    "s",      # rolling coordinate x_o + (l-r) sin(theta) + r theta [m]; ds/dt = v_x
    "xi",     # tangential deformation of the variant [m] (Eqs. 8, 11)
    "v_in",   # approach speed -v_y captured at the foot's touch-down [m/s] (anchors)
    "z",      # LuGre bristle deflection of the foot [m] (state BRISTLE; 0 under coulomb)
)

# Per-foot contact forces and their partial derivatives (docs/model.md section 4, Eqs. 3, 6, 7, 10, 11).
CONTACT = (
    "F_n",          # normal force, +Y [N]
    "F_t",          # tangential force, +X [N] (spring-damper + friction)
    "mu",           # friction coefficient mu(v_t) of Eq. 10 (0 when not in contact); under
                    # LuGre the friction force per unit normal force -(s0 z + s1 zdot + s2 v)
    "zdot",         # LuGre bristle rate dz/dt [m/s] (0 under coulomb and off contact)
    "z_rate",       # LuGre relaxation rate s0 |v| / g(v) of zdot = v - z_rate z [1/s] (0 under
                    # coulomb): the central difference method's exponential bristle update
    "dFn_ddelta",   # partial F_n / partial delta
    "dFn_ddeltad",  # partial F_n / partial delta_dot
    "dFt_dxi",      # partial F_t / partial xi
    "dFt_dv",       # partial F_t / partial v_x (includes F_n dmu/dv)
)

# The compiled ground (pdw/core/ground.py, pdw/core/csrc/pdw_ground.h, docs/terrain.md): one cell
# of the piecewise-quintic height table, h = sum_j a_j d^j with d = s - s_k [m] on the cell (the
# cell's width w_k = 1 / inv_w scales the arc-length table's u = d / w_k).
GROUND_CELL = ("s", "inv_w", "a0", "a1", "a2", "a3", "a4", "a5")
# The ground sampled under one foot (at s = x_A, the foot arc centre's distance along the slope),
# the inputs of the shaped-ground kinematics (derive/terrain.py).
GROUND = (
    "h",        # height of the surface above the mean slope [m]
    "dh",       # slope h'(s) [-]
    "ddh",      # h''(s) [1/m]
    "sigma",    # arc length of the surface from s_min [m] (the consistent variant's anchor)
    "alpha",    # surface angle atan(h') [rad]
    "inv_n",    # 1/N = 1/sqrt(1 + h'^2), computed once per foot and evaluation [-]
    "s_n",      # h'/N: the tangent's Y component (t = (1/N, h'/N)), the forces' coefficient [-]
)

# Energies (docs/model.md section 3).
ENERGY = ("T", "V_gravity", "V_hip")

# Contact flags carried as discrete state by every simulation.
FLAGS = ("leg1", "leg2")


# --- simulation records (the compiled time loops) -------------------------------------------
# One contact event (a support-flag change, docs/model.md section 5), a row of doubles.
EVENT = ("t", "leg", "kind", "x_D", "y_D")
EVENT_KIND = ("lift_off", "touch_down")
# Contact forces recorded per sample: foot-major.
RECORD_CONTACT = ("F_n1", "F_t1", "F_n2", "F_t2")
# Why a time loop returned.
STATUS = (
    "running",      # not finished (internal)
    "done",         # reached t_end (or the requested number of steps)
    "fell",         # the walker fell (hip too low, or a foot through the ground)
    "diverged",     # non-finite or runaway state
    "events_full",  # event buffer full: the caller grows it and resumes (internal)
    "singular",     # the step's linear system was singular
    "periodic",     # stopped because successive steps agree (gait converged)
)
# Why a time loop failed (pdw_failure.reason, PDW_REASON_*), with the message a Result and a
# DivergedError carry (pdw.Result.failure["reason"]).
REASON = (
    ("none", "none"),
    ("nonfinite", "a non-finite value (NaN or infinity) appeared in the state"),
    ("speed", "a velocity exceeded max_speed (runaway state)"),
    ("hip_low", "the hip dropped below fall_hip_height"),
    ("foot_deep", "a foot sank deeper than fall_depth below the ground"),
    ("singular", "the step's linear system was singular"),
    ("step_size", "the adaptive step size underflowed (the error test never passed)"),
    ("budget", "the step budget (max_steps) was used up before t_end"),
    ("off_ground", "the walker left the ground's defined extent (the hip came within a leg length "
                   "of Ground.s_range's ends; docs/terrain.md)"),
)
# Returns of a time loop that never reach a Result (PDW_STATUS_<NAME> = RESUME_BASE + i, apart
# from STATUS): the loop stops where it resumes exactly, its caller (pdw/core/_core.pyx run) does
# what the message says and calls it again.
RESUME_BASE = 64
RESUME = (
    ("records_full", "the record buffer is full: the caller doubles it, copying the samples, and "
                     "resumes (only adaptive methods and fixed-step runs of more than "
                     "RECORD_EXACT_MAX samples, whose buffers are not sized exactly, return it)"),
    ("poll", "poll_every loop iterations have passed: the caller checks for signals (Ctrl-C) and "
             "a cancelled pool's token, then resumes"),
)
# The record buffers and the poll of one run (pdw/core/_core.pyx run).
RECORD_CHUNK = 1 << 16          # first size of an adaptive run's record buffers [samples]
RECORD_EXACT_MAX = 1 << 24      # a fixed-step run's buffers hold its samples exactly up to this
POLL_EVERY = 2000               # loop iterations between two polls (0 in a run: never)
# Which stop condition of a scene ended a run before t_end (pdw_sim.stop_reason).
STOP = (
    "none",         # none did: the run reached t_end, or failed
    "steps",        # the requested number of complete gait steps was reached
    "periodic",     # the last k steps agreed within the tolerance
    "touch_down",   # the given leg touched down (the ensemble's Poincare maps)
)

# Per-step gait descriptors (docs/model.md section 8), computed online in the compiled loop as the
# events happen, with the definitions of pdw/sim/gait.py; one row of doubles per complete step.
STEP = (
    "leg",              # swing leg of the step (0 or 1, as in EVENT)
    "t_lift_off",       # its lift-off [s]
    "t_touch_down",     # its touch-down [s] (the step ends here)
    "L",                # step length: footprint spacing along X [m]
    "travel",           # the swing foot's own travel, lift-off to touch-down [m]
    "P",                # step period: lift-off to touch-down [s]
    "v",                # step velocity L / P [m/s]
    "cycle",            # time since the previous touch-down [s]
    "double_support",   # touch-down to the other leg's lift-off [s] (NaN: not (yet) known)
    "ds_fraction",      # double_support / cycle
)
# The online analysis keeps the last STEP_RING steps (a ring buffer: O(1) memory per run).
STEP_RING = 32
# The descriptors the periodic stop compares over the last k steps.
PERIODIC_FIELDS = ("L", "travel", "P", "cycle")


def work_layout():
    """Offsets of the per-evaluation scratch array ``work`` (all stage outputs).

    Returns
    -------
    list of (name, size)
    """
    return [
        ("kin", 2 * len(KIN)),
        ("contact", 2 * len(CONTACT)),
        ("M", NQ * NQ),
        ("f", NQ),
        ("qdd", NQ),
        ("ground", 2 * len(GROUND)),      # the ground sampled under each foot (shaped ground)
        ("ground_cell", 2),               # each foot's last height cell (a hint: pdw_ground.h)
    ]
