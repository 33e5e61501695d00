# The compiled ground (pdw/core/csrc/pdw_ground.h) as a Cython object over a GroundTable's
# arrays (pdw/core/ground_table.py); included by _core.pyx and _batch.pyx.
import numpy as _np_ground


cdef extern from "pdw_model.h":
    enum:
        PDW_NGCELL


cdef extern from "pdw_ground.h":
    ctypedef struct pdw_ground:
        double s_min, s_max
        long n_cells
        const double *cells
        const double *arc
        long n_lut
        double lut_inv
        const long *lut
        int n_patches, n_fields
        const int *fields
        const double *patches
        double blend
        int n_zones
        const double *zones
    void pdw_ground_set_bounds(pdw_ground *g) noexcept nogil


cdef class CGround:
    """A `pdw.core.ground_table.GroundTable` as the C struct pdw_ground (its arrays kept alive)."""
    cdef pdw_ground g
    cdef object keep

    def __init__(self, table):
        cells = _np_ground.ascontiguousarray(table.cells, dtype=_np_ground.float64)
        arc = _np_ground.ascontiguousarray(table.arc, dtype=_np_ground.float64)
        lut = _np_ground.ascontiguousarray(table.lut, dtype=_np_ground.int64)
        fields = _np_ground.ascontiguousarray(table.patch_fields, dtype=_np_ground.intc)
        patches = _np_ground.ascontiguousarray(table.patches, dtype=_np_ground.float64).reshape(-1)
        zones = _np_ground.ascontiguousarray(table.zones, dtype=_np_ground.float64)
        if cells.ndim != 2 or cells.shape[1] != PDW_NGCELL or cells.shape[0] < 1:
            raise ValueError("ground table: cells must have shape (n >= 1, %d)" % PDW_NGCELL)
        if arc.shape != (cells.shape[0], 6) or lut.ndim != 1 or lut.shape[0] < 1:
            raise ValueError("ground table: arc (n, 6) and lut (m >= 1,) expected")
        if lut.min() < 0 or lut.max() >= cells.shape[0]:
            raise ValueError("ground table: lut entries out of range")
        if patches.shape[0] != table.patches.shape[0] * (2 + fields.shape[0]):
            raise ValueError("ground table: patches must have shape (p, 2 + fields)")
        if not (table.s_max > table.s_min and table.lut_inv > 0 and table.lut_inv < 1e300
                and table.blend > 0 and table.blend < 1e300):
            raise ValueError("ground table: need s_max > s_min, 0 < lut_inv, blend finite")
        if not (_np_ground.all(_np_ground.isfinite(cells)) and _np_ground.all(_np_ground.isfinite(arc))
                and _np_ground.all(_np_ground.isfinite(zones))):
            raise ValueError("ground table: cells, arc and zones must be finite")
        if fields.shape[0] and (fields.min() < 0 or fields.max() >= PDW_NP):
            raise ValueError("ground table: patch fields out of range")
        self.keep = (cells, arc, lut, fields, patches, zones)
        cdef double[:, ::1] vc = cells
        cdef double[:, ::1] va = arc
        cdef long[::1] vl = lut
        self.g.s_min = table.s_min
        self.g.s_max = table.s_max
        self.g.n_cells = cells.shape[0]
        self.g.cells = &vc[0, 0]
        self.g.arc = &va[0, 0]
        self.g.n_lut = lut.shape[0]
        self.g.lut_inv = table.lut_inv
        self.g.lut = &vl[0]
        self.g.n_patches = table.patches.shape[0]
        self.g.n_fields = fields.shape[0]
        self.g.blend = table.blend
        self.g.n_zones = zones.shape[0]
        cdef int[::1] vf
        cdef double[::1] vp, vz
        if fields.shape[0]:
            vf = fields
            self.g.fields = &vf[0]
        if patches.shape[0]:
            vp = patches
            self.g.patches = &vp[0]
        if zones.shape[0]:
            vz = zones
            self.g.zones = &vz[0]
        pdw_ground_set_bounds(&self.g)
