/* The registry of compiled integrators (see the contract in pdw_sim.h). Python mirrors it in
 * pdw/integrators.py; the order of this table is the method id. */
#include "pdw_sim.h"

const pdw_method pdw_methods[] = {
    {"cdm", 1, 0, pdw_cdm_advance},
};

const int pdw_nmethods = (int)(sizeof pdw_methods / sizeof pdw_methods[0]);
