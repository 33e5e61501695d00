"""Simple cell mapping (Hsu 1980, 1987) of the continuous walker's touch-down map: periodic cells
and basins of attraction on a 2-D grid of the Poincaré section (the paper's method, Sec. 3.2,
ref. [34]; docs/studies.md, "Cell mapping").

The section and its coordinates are those of `pdw.limit_cycle` (touch-down of the swing foot,
legs relabelled, z = (theta1, theta2, xd_o, yd_o, thetad1, thetad2), leg 2 just touched down).
The grid is 2-D, over

    a = phi = theta2 - theta1     the inter-leg angle at touch-down                  [rad]
    b = thetad2                   the swing (touching-down) leg's angular velocity   [rad/s]

the two coordinates that carry the gait's slow dynamics (the dominant Floquet pair's
eigenvectors lie mostly along thetad2 and phi; the other four multipliers are below 0.02 at
`Params.paper_steady()`, so one step brings any state close to a 2-D slow manifold). The other
four coordinates of a cell's centre state are *fixed* or *derived*: the mean leg angle
m = (theta1 + theta2)/2, the trailing leg's rate thetad1 and the trailing (stance) foot's
material-point velocity (v_x1, v_y1) are those of a reference section point (default: the first
touch-down of the paper's initial condition, `reference_point`, which does not use the fixed
point); the hip velocity is derived from them (`cell_state`), so that changing phi does not
kick the stance foot. (Keeping the hip velocity itself fixed would change the stance foot's
velocity by ~1 cm/s per 0.025 rad of phi.) A contact law with extra section coordinates
(`pdw.limit_cycle.section_names`: LuGre's trailing bristle, the trailing approach speed of
lankarani_nikravesh and flores) has them fixed at the reference point's values too, and
``contact=`` goes with the step-map options.

The slice map is very steep in phi: at `Params.paper_steady()` the image's thetad2 changes by
about -25 rad/s per rad of phi (the next touch-down's timing moves the swing leg along its
pendulum swing), while the image's phi hardly depends on either coordinate. Cells must
therefore be narrow in phi (the default grid: 0.0015 rad x 0.035 rad/s).

Cell-to-cell map: the image of a cell is the cell containing (a, b) of P(centre); a step that
fails (fell, no touch-down, flight) or an image outside the grid goes to the *sink*. The
periodic groups (cycles of the cell map) are the attractors; every cell gets its group (or
the sink) and the number of steps to reach it (Hsu's unravelling algorithm, `unravel`).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...core import checks, interrupt
from ...core.errors import InvalidInputError
from ...core.params import X0_PAPER, Params
from ...core.progress import progress_bar
from ..stepmap import poincare as _poincare
from ..stepmap import section as _section
from ..stepmap import step_maps as _maps

SINK = -1
GRID = ("phi", "thetad2")


def reference_point(params=None, variant="paper", method="rodas4", contact=None):
    """The section point (`pdw.limit_cycle.section_names` (contact)) of the first touch-down of
    the paper's initial condition (X0_PAPER, flags (0, 1)) under ``contact``; None if the
    walker does not get there."""
    return _section.settle(X0_PAPER, params, variant, method, flags0=(0, 1), t_end=0.6,
                     contact=contact)


def cell_state(a, b, rest, params):
    """Section point z of grid coordinates (phi, thetad2) and the other coordinates ``rest`` =
    (mean angle m, trailing foot's velocity v_x1, v_y1, thetad1, then the contact law's extra
    section coordinates, if any, copied to z's end): theta1 = m - phi/2,
    theta2 = m + phi/2, and the hip velocity follows from the trailing foot's material-point
    velocity (docs/model.md section 2, consistent rate): xd_o = v_x1 - ((l - r) cos theta1 + r)
    thetad1, yd_o = v_y1 - (l - r) sin theta1 thetad1."""
    m, vx, vy, w1 = rest[:4]
    th1, th2 = m - 0.5 * a, m + 0.5 * a
    lr = params.l - params.r
    return np.array([th1, th2, vx - (lr * np.cos(th1) + params.r) * w1,
                     vy - lr * np.sin(th1) * w1, w1, b, *rest[4:]])


def rest_of(z, params):
    """The non-grid coordinates (m, v_x1, v_y1, thetad1, then z's extras beyond the six
    mechanical ones: `pdw.limit_cycle.section_names`) of section point(s) z."""
    z = np.asarray(z, dtype=float)
    th1, w1 = z[..., 0], z[..., 4]
    lr = params.l - params.r
    vx = z[..., 2] + (lr * np.cos(th1) + params.r) * w1
    vy = z[..., 3] + lr * np.sin(th1) * w1
    return np.concatenate([np.stack([0.5 * (z[..., 0] + z[..., 1]), vx, vy, w1], axis=-1),
                           z[..., 6:]], axis=-1)


def grid_of(z):
    """(phi, thetad2) of section point(s) z."""
    z = np.asarray(z, dtype=float)
    return np.stack([z[..., 1] - z[..., 0], z[..., 5]], axis=-1)


def unravel(image):
    """Hsu's unravelling of a simple cell map.

    ``image[c]`` is the image cell of cell c (0..N-1) or `SINK`. Returns (group, steps,
    periodic): ``group[c]`` the periodic group cell c ends in (`SINK` for the sink), ``steps[c]``
    the number of mappings to reach it (0 for periodic cells), ``periodic`` the list of groups,
    each an array of cells in cycle order (its period is its length).
    """
    image = np.asarray(image, dtype=int)
    N = len(image)
    UNSEEN = -2
    group = np.full(N, UNSEEN, dtype=int)
    steps = np.full(N, -1, dtype=int)
    periodic = []
    for c0 in range(N):
        if group[c0] != UNSEEN:
            continue
        path, pos, cur = [], {}, c0
        while True:
            if cur == SINK:
                g, s_end = SINK, 0
                break
            if cur in pos:                                # closed a new cycle
                cyc = path[pos[cur]:]
                g = len(periodic)
                periodic.append(np.array(cyc, dtype=int))
                group[cyc] = g
                steps[cyc] = 0
                path = path[:pos[cur]]
                s_end = 0
                break
            if group[cur] != UNSEEN:                      # reached a processed cell
                g, s_end = group[cur], steps[cur]
                break
            pos[cur] = len(path)
            path.append(cur)
            cur = int(image[cur])
        for k, q in enumerate(reversed(path)):
            group[q] = g
            steps[q] = s_end + k + 1
    return group, steps, periodic


@dataclass
class CellMap:
    """Outcome of `cell_map`. Cells are numbered c = i * nb + j (i along a = phi, j along
    b = thetad2); 2-D views by ``.reshape(na, nb)``.

    Attributes
    ----------
    a_edges, b_edges : ndarray
        Cell edges along phi [rad] and thetad2 [rad/s].
    image : ndarray (N,)
        Image cell of each cell, or `SINK`.
    status : ndarray (N,) of str
        The step's status from each cell's centre ("ok", "fell", ...; "left" for an image
        outside the grid).
    image_point : ndarray (N, 6)
        P(centre) (NaN where the step failed).
    rest : ndarray (N, 4)
        The four non-grid coordinates used at each cell's centre.
    group, steps : ndarray (N,)
        `unravel`'s result.
    periodic : list of ndarray
        Periodic groups (cycles of cells).
    """

    a_edges: np.ndarray
    b_edges: np.ndarray
    image: np.ndarray
    status: np.ndarray
    image_point: np.ndarray
    rest: np.ndarray
    group: np.ndarray
    steps: np.ndarray
    periodic: list
    params: Params | None = None
    variant: str = "paper"
    info: dict = field(default_factory=dict)

    @property
    def shape(self):
        return (len(self.a_edges) - 1, len(self.b_edges) - 1)

    def centers(self):
        """(A, B): the cell centres, each of shape (N,)."""
        a = 0.5 * (self.a_edges[1:] + self.a_edges[:-1])
        b = 0.5 * (self.b_edges[1:] + self.b_edges[:-1])
        A, B = np.meshgrid(a, b, indexing="ij")
        return A.ravel(), B.ravel()

    def cell_of(self, a, b):
        """The cell containing (a, b), or `SINK` outside the grid (int for scalar a, b)."""
        c = _cell_index(self.a_edges, self.b_edges, a, b)
        return int(c) if np.ndim(c) == 0 else c

    def periodic_cells(self):
        """List of (period, cells, centre of mass (phi, thetad2)) of the periodic groups."""
        A, B = self.centers()
        return [(len(g), g, (float(A[g].mean()), float(B[g].mean()))) for g in self.periodic]

    def basin(self, g):
        """Boolean mask (N,) of the cells that end in periodic group g (its domain of attraction)."""
        return self.group == g

    def summary(self):
        na, nb = self.shape
        lines = ["cell map %d x %d over phi [%.3f, %.3f] rad, thetad2 [%.3f, %.3f] rad/s: "
                 "%d periodic group(s), %d sink cells"
                 % (na, nb, self.a_edges[0], self.a_edges[-1], self.b_edges[0], self.b_edges[-1],
                    len(self.periodic), int(np.sum(self.group == SINK)))]
        for k, (n, _cells, (a, b)) in enumerate(self.periodic_cells()):
            lines.append("  group %d: period %d, centre phi = %.4f, thetad2 = %.4f, basin %d cells"
                         % (k, n, a, b, int(np.sum(self.group == k))))
        return "\n".join(lines)


def _cell_index(a_edges, b_edges, a, b):
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    i = np.searchsorted(a_edges, a, side="right") - 1
    j = np.searchsorted(b_edges, b, side="right") - 1
    na, nb = len(a_edges) - 1, len(b_edges) - 1
    ok = np.isfinite(a) & np.isfinite(b) & (i >= 0) & (i < na) & (j >= 0) & (j < nb)
    return np.where(ok, i * nb + j, SINK)


#: Most cells of one grid axis (`grid_axis`): a cell is at least one step map.
MAX_GRID = 10 ** 6


def grid_axis(name, spec):
    """(lo, hi, n) of a grid axis given as (lo, hi, n): finite lo < hi, an integer n in
    [1, `MAX_GRID`] (no 1.5 read as 1, no 2**62: `InvalidInputError` naming the axis)."""
    try:
        lo, hi, n = spec
    except (TypeError, ValueError):
        raise InvalidInputError("%s must be (lo, hi, n), got %r" % (name, spec)) from None
    lo, hi = checks.number(name + "[0] (lo)", lo), checks.number(name + "[1] (hi)", hi)
    if not hi > lo:
        raise InvalidInputError("%s must have lo < hi, got %r" % (name, spec))
    return lo, hi, checks.count(name + "[2] (n)", n, lo=1, hi=MAX_GRID)


def cell_map(params=None, variant="paper", phi=(0.69, 0.81, 80), thetad2=(-3.2, -0.4, 80), *,
             reference=None, method="rodas4", workers=None, progress=False, **options) -> CellMap:
    """Simple cell mapping of the touch-down map on a (phi, thetad2) grid.

    Parameters
    ----------
    params : Params
        Default `Params.paper_steady()`.
    phi, thetad2 : (lo, hi, n)
        The grid: n cells between lo and hi in each coordinate.
    reference : array_like (len(section_names(contact)),), optional
        Section point whose non-grid coordinates the cells use (default `reference_point`).
    workers : int
        Threads for the map evaluations (default: all cores).
    progress : bool or pdw.Progress
        A bar over the cells on stderr when it is a terminal (`pdw.core.progress`).
    options
        Step-map options (default `pdw.limit_cycle.LOOSE`: rtol 1e-7), ``contact`` among them:
        a law with extra section coordinates (LuGre's trailing bristle, lankarani_nikravesh's
        and flores's trailing approach speed) takes them from the reference point, as the
        four non-grid mechanical coordinates.

    Returns
    -------
    CellMap
    """
    p = Params.paper_steady() if params is None else params
    opts = {**_section.LOOSE, **options}
    (a0, a1, na), (b0, b1, nb) = grid_axis("phi", phi), grid_axis("thetad2", thetad2)
    a_edges = np.linspace(a0, a1, int(na) + 1)
    b_edges = np.linspace(b0, b1, int(nb) + 1)
    contact = options.get("contact")
    z_ref = (reference_point(p, variant, method, contact) if reference is None
             else _poincare._z(reference, "reference", contact))
    if z_ref is None:
        raise InvalidInputError("no reference point: the paper's initial condition does not "
                                "reach a touch-down with these parameters; pass reference=")
    N = int(na) * int(nb)
    rest = np.tile(rest_of(z_ref, p), (N, 1))
    A = np.repeat(0.5 * (a_edges[1:] + a_edges[:-1]), int(nb))
    B = np.tile(0.5 * (b_edges[1:] + b_edges[:-1]), int(na))
    Z = np.array([cell_state(A[c], B[c], rest[c], p) for c in range(N)])
    # through the ensemble engine where it takes the maps (the same numbers as `_poincare.step`)
    image_point, status = _maps.map_images(Z, p, variant, method, workers=workers, t_hint=0.6,
                                        progress=progress, **opts)
    g = grid_of(image_point)
    image = _cell_index(a_edges, b_edges, g[:, 0], g[:, 1])
    left = (image == SINK) & (status == "ok")
    status[left] = "left"
    group, steps, periodic = unravel(image)
    return CellMap(a_edges=a_edges, b_edges=b_edges, image=image, status=status.astype(str),
                   image_point=image_point, rest=rest, group=group, steps=steps,
                   periodic=periodic, params=p, variant=variant,
                   info=dict(reference=z_ref, evaluations=N, options=opts, method=method))


def plot_basin(cm: CellMap, ax=None, fixed_point=None, title=None, max_steps=8):
    """Draw the cell map: the basins of the periodic groups (blue shades: darker = fewer
    steps to the periodic cells, up to ``max_steps``), the sink (dark grey: the walker falls
    from the cell itself; light grey: later, or the image leaves the grid), the periodic cells
    (black squares) and a Newton fixed point (``fixed_point`` = (phi, thetad2), a cross).
    Returns the axes."""
    import matplotlib.pyplot as plt
    from matplotlib.colors import ListedColormap

    if ax is None:
        _, ax = plt.subplots(figsize=(6.4, 5))
    na, nb = cm.shape
    sink = cm.group == SINK
    at_once = sink & ~np.isin(cm.status, ("ok", "left"))
    grey = np.where(sink, np.where(at_once, 0.0, 1.0), np.nan).reshape(na, nb).T
    ax.pcolormesh(cm.a_edges, cm.b_edges, grey, cmap=ListedColormap(["#4d4d4d", "#b0b0b0"]),
                  vmin=-0.5, vmax=1.5, shading="flat")
    steps = np.where(~sink, np.minimum(cm.steps, max_steps), np.nan).reshape(na, nb).T
    mesh = ax.pcolormesh(cm.a_edges, cm.b_edges, steps, cmap="Blues_r", vmin=0,
                         vmax=max_steps + 2, shading="flat")
    cb = plt.colorbar(mesh, ax=ax, ticks=range(0, max_steps + 1, 2))
    cb.set_label("steps to the periodic cell (basin)")
    A, B = cm.centers()
    for g in cm.periodic:
        ax.plot(A[g], B[g], "ks", ms=3)
    if fixed_point is not None:
        ax.plot(*fixed_point, "wx", ms=9, mew=2)
        ax.plot(*fixed_point, "rx", ms=7, mew=1)
    ax.set_xlabel(r"inter-leg angle at touch-down $\phi = \theta_2 - \theta_1$ [rad]")
    ax.set_ylabel(r"swing leg's rate at touch-down $\dot\theta_2$ [rad/s]")
    if title:
        ax.set_title(title, fontsize=9)
    return ax


def point_mapping_basin(cm: CellMap, z_star, *, n_steps=12, tol=1e-4, workers=None,
                        progress=False, **options):
    """Check of a cell map against the full dynamics: from every cell's centre state, iterate
    the touch-down map (the whole section: 6-D, more with a law's extras; no cells) up to
    ``n_steps`` steps; a cell is in the basin when the orbit comes within ``tol`` (max norm) of
    the fixed point ``z_star``.

    Returns (converged, steps): boolean mask (N,) and the number of steps taken (N,) (-1 when
    a step failed). ``progress``: False, True or a `pdw.Progress` (one unit per cell).
    """
    p = cm.params
    opts = {**cm.info.get("options", _section.LOOSE), **options}
    A, B = cm.centers()
    Z = np.array([cell_state(A[c], B[c], cm.rest[c], p) for c in range(len(A))])
    z_star = np.asarray(z_star, dtype=float)
    fn = lambda z: _converge(z, z_star, n_steps, tol, p, cm.variant, cm.info.get("method", "rodas4"), opts)  # noqa: E731
    nw = min(_maps._workers(workers), len(Z))
    bar = progress_bar(progress, len(Z), "point mapping")
    outs = interrupt.thread_map(fn, Z, nw, bar)        # Ctrl-C stops every thread
    return np.array([o[0] for o in outs]), np.array([o[1] for o in outs])


def _converge(z, z_star, n_steps, tol, p, variant, method, opts):
    t_hint = 0.6
    for k in range(1, n_steps + 1):
        s = _poincare.step(z, p, variant, method, t_hint=t_hint, **opts)
        if s["status"] != "ok":
            return False, -1
        z, t_hint = s["z"], s["period"]
        if np.max(np.abs(z - z_star)) < tol:
            return True, k
    return False, n_steps
