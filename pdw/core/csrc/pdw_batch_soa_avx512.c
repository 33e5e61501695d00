/* The structure-of-arrays steps for instruction set "avx512": the cdm step (pdw_batch_soa.inc)
 * and rodas4's try step (pdw_batch_ros.inc). pdw_batch.c and pdw_batch_ros.c call them only
 * where the CPU has it (pdw_batch_isa_supported). ISO C mode (-std=c99) keeps FMA contraction
 * off, so every target gives the same bits (vector sin/cos aside). */
#define PDW_SOA_FN(name) name##_avx512
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#pragma GCC target("avx512f,avx512vl,avx512dq,avx512bw")
#endif
#include "pdw_batch_soa.inc"
#include "pdw_batch_ros.inc"
