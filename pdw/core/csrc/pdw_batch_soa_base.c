/* The structure-of-arrays cdm step (pdw_batch_soa.inc) for instruction set "base"; pdw_batch.c
 * calls it only where the CPU has it (pdw_batch_isa_supported). ISO C mode (-std=c99) keeps FMA
 * contraction off, so every target gives the same bits (vector sin/cos aside). */
#define PDW_SOA_FN(name) name##_base
#include "pdw_batch_soa.inc"
