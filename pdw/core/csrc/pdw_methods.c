/* The registry of compiled integrators (see the contract in pdw_sim.h). Python mirrors it in
 * pdw/core/integrators.py; the order of this table is the method id. */
#include "pdw_sim.h"

const pdw_method pdw_methods[] = {
    {"cdm", 1, 0, pdw_cdm_advance},
    {"verlet", 2, 0, pdw_verlet_advance},
    {"rk4", 4, 0, pdw_rk4_advance},
    {"dopri5", 5, 1, pdw_dopri5_advance},
    {"rodas4", 4, 1, pdw_rodas4_advance},
};

const int pdw_nmethods = (int)(sizeof pdw_methods / sizeof pdw_methods[0]);
