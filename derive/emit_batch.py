"""Emit ``generated/pdw_batch_gen.h``: structure-of-arrays (SoA) variants of the stages.

The cdm lane loop (pdw/core/csrc/pdw_batch_soa.inc) takes kinematics, contact and cdm_terms;
rodas4's (pdw/core/csrc/pdw_batch_ros.inc) kinematics, contact and dynamics for its right-hand
side, and contact_partials and dynamics_jacobian for its Jacobian.

A batched stage computes one stage of the scalar kernel for W walkers at once, one per lane:
every array of the scalar stage (``x``, ``p``, ``trig``, ``anchors``, ``kin``, ``contact``,
``M``, ``C``, ``QmG``) becomes lane-minor, element ``a[i]`` of lane ``l`` at
``a[i*PDW_SOA + l]`` (``PDW_SOA`` = 72: room for the most lanes, 64, and not a power of
two, so that the rows a stage touches fall in different cache sets), and the body runs in a
``#pragma omp simd`` loop over the lanes that the C compiler vectorizes (one lane per SIMD
slot). The expressions are the scalar stages' (`derive.stages`), eliminated by the same
`derive.printer.c_block` into the same statements, so a lane computes exactly the scalar
kernel's operations in the same order; they use only + - * / sqrt fabs and comparisons, all
correctly rounded in SIMD, so with no FMA contraction (ISO C mode) a lane's result is bitwise
the scalar one. The contact stage's branch (a penetrating support foot) becomes a mask: every
lane evaluates the force law and keeps it only where its foot is one (``on ? force : 0.0``).

The functions are ``static``: the header is included by each instruction-set variant of the
lane loop (pdw/core/csrc/pdw_batch_soa.inc), compiled once per target (run-time dispatch,
docs/ensemble.md). Kernels with a normal law other than Hunt-Crossley or a friction law other
than the smooth Coulomb one have no batched stages (NULL in the table): the lane loop then runs
them through the scalar stages (or the batch refuses them).

Deterministic, stamped with `derive.emit.input_hash` like the other generated files.
"""
from __future__ import annotations

import re

from . import layout, stages
from . import model as mdl

_ELEM = re.compile(r"^(\w+)\[(.+)\]$")


def _soa(ref: str) -> str:
    """``a[i]`` -> ``a[(i)*PDW_SOA + l]``; a local name stays as it is."""
    m = _ELEM.match(ref)
    return ref if m is None else "%s[(%s)*PDW_SOA + l]" % (m.group(1), m.group(2))


# lanes in chunks of PDW_SOA_CHUNK = 8 (a constant trip count, a multiple of every vector
# width: no scalar remainder, no profitability threshold at run time; a block of W lanes
# computes ceil(W/8)*8, the padding lanes' values unused)
LOOP = ("    for (int l0 = 0; l0 < W; l0 += PDW_SOA_CHUNK) {\n"
        "    #pragma omp simd\n    for (int l = l0; l < l0 + PDW_SOA_CHUNK; ++l) {\n%s\n    }\n    }")


def _function(signature, body):
    return "%s\n{\n%s\n}\n" % (signature, body)


def emit_kernel(spec, names, c_block, nforces):
    """C source of the batched stages of one kernel: kinematics, contact, cdm_terms (the cdm lane
    loop), contact_partials, dynamics and dynamics_jacobian (the rodas4 lane loop)."""
    k = "pdw_soa_" + spec.name
    soa = {s: _soa(c) for s, c in names.items()}
    out = ["/* ---- kernel %s, batched (SoA) ---- */\n" % spec.name]

    targets = [_soa("kin[%d*PDW_NKIN + PDW_KIN_%s]" % (i, f.upper()))
               for i in range(2) for f in layout.KIN]
    code, _ = c_block(stages.kinematics(spec), targets, soa, indent="        ")
    out.append(_function(
        "static void %s_kinematics(int W, const double *restrict x, const double *restrict trig,\n"
        "    const double *restrict p, const double *restrict anchors, double *restrict kin)" % k,
        "    (void)anchors;\n" + LOOP % code))

    for suffix, nout in (("contact", nforces), ("contact_partials", len(layout.CONTACT))):
        out.append(_contact_function(k + "_" + suffix, stages.contact(spec)[:nout],
                                     layout.CONTACT[:nout], soa, c_block))
    # the cdm lane loop's contact stage: the friction law's parameter-only temporaries (its
    # divisions by v_d - v_s, ...) once per walker, into rows kc
    # ... and the cdm lanes' kinematics, flag rules (PDW_SOA_RULES, pdw_batch_soa.inc) and
    # contact stage in one lane loop, the kinematics in locals kin_<leg>_<FIELD>
    kin_locals = ["kin_%d_%s" % (i, f.upper()) for i in range(2) for f in layout.KIN]
    kin_code, _ = c_block(stages.kinematics(spec), kin_locals, soa, tmp_prefix="tk",
                          indent="            ")
    consts, kin_contact, nkc = _contact_consts(k, stages.contact(spec)[:nforces], soa, c_block,
                                               kin_code, kin_locals)
    out += [consts, kin_contact, "enum { %s_NKC = %d };\n" % (k.upper(), nkc)]
    # the cdm lanes' cdm_terms and update in one lane loop: M, C and Q_f - G into locals
    # M_i_j, C_i_j, QmG_i (the scalar stage's statements, so the same bits), then
    # PDW_SOA_CDM_UPDATE (pdw/core/csrc/pdw_batch_soa.inc, defined before this header)
    local = ["M_%d_%d" % divmod(i, 4) for i in range(16)] + ["C_%d_%d" % divmod(i, 4)
                                                            for i in range(16)] \
        + ["QmG_%d" % i for i in range(4)]
    code, _ = c_block(stages.cdm_terms(spec), local, soa, indent="        ")
    decl = "        double %s;\n" % ", ".join(local)
    unused = "        %s\n" % " ".join("(void)%s;" % v for v in local)
    out.append(_function(
        "static void %s_cdm_update(int W, double *restrict x, double *restrict u_prev,\n"
        "    const double *restrict trig, const double *restrict p, const double *restrict contact,\n"
        "    const double *restrict hip, const double *restrict kinv, long long *restrict armed,\n"
        "    const long long *restrict armed_next, long long *restrict rare, double idt2,\n"
        "    double ih, double max_speed)" % k,
        LOOP % (decl + code + "\n" + unused + "        PDW_SOA_CDM_UPDATE")))
    # M[2][2] and M[3][3] alone (the update's cached inverses): the same statements (the
    # compiler drops those the two do not need), so the same bits as cdm_update's
    out.append(_function(
        "static void %s_mdiag(int W, const double *restrict x, const double *restrict trig,\n"
        "    const double *restrict p, const double *restrict contact, double *restrict md)" % k,
        LOOP % (decl + code + "\n" + unused
                + "        md[0*PDW_SOA + l] = M_2_2;\n        md[1*PDW_SOA + l] = M_3_3;")))

    # the right-hand side's and the Jacobian's stages (the lane loop of rodas4, pdw_batch_ros.inc)
    targets = [_soa("M[%d]" % i) for i in range(16)] + [_soa("f[%d]" % i) for i in range(4)]
    code, _ = c_block(stages.dynamics(spec), targets, soa, indent="        ")
    out.append(_function(
        "static void %s_dynamics(int W, const double *restrict x, const double *restrict trig,\n"
        "    const double *restrict p, const double *restrict contact,\n"
        "    double *restrict M, double *restrict f)" % k, LOOP % code))

    targets = [_soa("A[%d]" % i) for i in range(32)]
    code, _ = c_block(stages.dynamics_jacobian(spec), targets, soa, indent="        ")
    out.append(_function(
        "static void %s_dynamics_jacobian(int W, const double *restrict x,\n"
        "    const double *restrict trig, const double *restrict p, const double *restrict contact,\n"
        "    const double *restrict qdd, double *restrict A)" % k, LOOP % code))
    return "\n".join(out)


_FUNCS = {"sqrt", "fabs", "pow", "exp", "expm1", "log", "sin", "cos", "tanh", "atan", "fmin",
          "fmax"}
_TEMP = re.compile(r"^\s*const double (t\d+) = (.*);$")
_IDENT = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


def _hoist(code):
    """Split the lane loop's code (c_block's lines) into the temporaries that depend on the
    parameters only (pv_* locals) and the rest: (per-step lines, per-walker lines, the
    per-walker temporaries the per-step lines read). The per-walker lines are the very same
    statements, so a lane that reads their values from rows computed once per walker gets
    the same bits."""
    const, step, names = set(), [], []
    walker = []
    for line in code.split("\n"):
        m = _TEMP.match(line)
        if m and all(w.startswith("pv_") or w in const or w in _FUNCS
                     for w in _IDENT.findall(m.group(2))):
            const.add(m.group(1))
            walker.append(line)
        else:
            step.append(line)
    used = set().union(*(set(_IDENT.findall(line)) for line in step)) if step else set()
    names = [t for t in (_TEMP.match(line).group(1) for line in walker) if t in used]
    return step, walker, names


def _loads(pre, text, indent="            "):
    """The parameter loads the code in text reads."""
    used = set(_IDENT.findall(text))
    return "".join("%sconst double %s = %s;\n" % (indent, v, load)
                   for v, load in sorted(pre.items()) if v in used)


def _contact_consts(k, exprs, soa, c_block, kin_code, kin_locals):
    """The contact stage with its parameter-only temporaries read from rows kc (computed once
    per walker by fname_consts): (the two functions' C, the number of kc rows)."""
    used = set().union(*(e.free_symbols for e in exprs))
    pre = {s_: "pv_%s" % n for n, s_ in mdl.P.items() if s_ in used}
    outs = ["o_%s" % f.lower() for f in layout.CONTACT[:len(exprs)]]
    code, _ = c_block(exprs, outs, {**soa, **pre}, indent="            ")
    step, walker, names = _hoist(code)
    loads = {v: soa[s_] for s_, v in pre.items()}
    body_w = "\n".join(walker)
    consts = _function(
        "static void %s_contact_consts(int W, const double *restrict p, double *restrict kc)" % k,
        "    for (int l0 = 0; l0 < W; l0 += PDW_SOA_CHUNK) {\n"
        "    #pragma omp simd\n"
        "    for (int l = l0; l < l0 + PDW_SOA_CHUNK; ++l) {\n"
        + _loads(loads, body_w, "        ") + body_w.replace("            ", "        ") + "\n"
        + "".join("        kc[%d*PDW_SOA + l] = %s;\n" % (j, t) for j, t in enumerate(names))
        + "    }\n    }")
    reads = "".join("            const double %s = kc[%d*PDW_SOA + l];\n" % (t, j)
                    for j, t in enumerate(names))
    body_s = "\n".join(step)
    return consts, _kin_contact(k + "_kin_contact", kin_code, kin_locals,
                                _loads(loads, body_s) + reads + body_s,
                                layout.CONTACT[:len(exprs)], outs), len(names)


# the inputs of the law from leg i's kinematics (locals kin_<i>_<FIELD>), as the scalar
# stage takes them
_INPUTS = (("delta", "-kin_%s_Y_D"), ("deltad", "-kin_%s_V_Y"), ("v_t", "kin_%s_V_X"),
           ("xi", "kin_%s_XI"), ("v_in", "kin_%s_V_IN"))


def _kin_contact(fname, kin_code, kin_locals, code, fields, outs):
    """The cdm lanes' kinematics, flag rules and contact stage in one lane loop, the kinematics
    in locals (kin_code: the scalar stage's statements into kin_locals, the same bits), the
    rules PDW_SOA_RULES (pdw/core/csrc/pdw_batch_soa.inc, defined before this header). The force
    law once per lane, for leg 0 where it is a penetrating support foot and else for leg 1,
    and a second pass (the kinematics again, then leg 1's law) only when a lane of the block
    has both feet on (double support, rare): a swing leg's law is not computed (the scalar
    stage's branch skips it). Each evaluation is the law's statements on that leg's inputs,
    the same bits as the scalar stage."""
    def law(pick):
        ins = "".join("            const double %s = %s;\n" % (v, pick(src)) for v, src in _INPUTS)
        return (ins + "            (void)delta; (void)deltad; (void)v_t; (void)xi; (void)v_in;\n"
                "            double %s;\n%s\n" % (", ".join(outs), code))

    def sel(src):
        neg, name = ("-", src[1:]) if src.startswith("-") else ("", src)
        return "%s(on0 ? %s : %s)" % (neg, name % 0, name % 1)
    kin = ("            double %s;\n" % ", ".join(kin_locals) + kin_code + "\n"
           + "            %s\n" % " ".join("(void)%s;" % v for v in kin_locals))
    on = ("            const long long on0 = (flags[l] != 0) & (kin_0_Y_D < 0.0);\n"
          "            const long long on1 = (flags[PDW_SOA + l] != 0) & (kin_1_Y_D < 0.0);\n")
    first = "\n".join(
        "            c0[PDW_CONTACT_%s*PDW_SOA + l] = on0 ? %s : 0.0;\n"
        "            c1[PDW_CONTACT_%s*PDW_SOA + l] = (on1 & !on0) ? %s : 0.0;"
        % (f.upper(), o, f.upper(), o) for f, o in zip(fields, outs))
    second = "\n".join(
        "            const double w_%s = c1[PDW_CONTACT_%s*PDW_SOA + l];\n"
        "            c1[PDW_CONTACT_%s*PDW_SOA + l] = (on0 & on1) ? %s : w_%s;"
        % (o, f.upper(), f.upper(), o, o) for f, o in zip(fields, outs))
    return _function(
        "static void %s(int W, const double *restrict x, const double *restrict trig,\n"
        "    const double *restrict p, const double *restrict anchors, const double *restrict kc,\n"
        "    const long long *restrict flags, const long long *restrict armed,\n"
        "    const long long *restrict upd, const double *restrict depth,\n"
        "    long long *restrict armed_next, long long *restrict rare, double *restrict contact)"
        % fname,
        "    double *restrict c0 = contact, *restrict c1 = contact + PDW_NCONTACT*PDW_SOA;\n"
        "    long long both = 0;\n"
        "    (void)anchors;\n"
        "    for (int l0 = 0; l0 < W; l0 += PDW_SOA_CHUNK) {\n"
        "    #pragma omp simd reduction(|:both)\n"
        "    for (int l = l0; l < l0 + PDW_SOA_CHUNK; ++l) {\n"
        + kin + "            PDW_SOA_RULES\n" + on + "            both |= on0 & on1;\n"
        "            /* the law for leg 0 if it is a penetrating support foot, else for leg 1 */\n"
        + law(sel) + first + "\n        }\n    }\n"
        "    if (!both) return;\n"
        "    /* double support: leg 1's own law where both feet are on */\n"
        "    for (int l0 = 0; l0 < W; l0 += PDW_SOA_CHUNK) {\n"
        "    #pragma omp simd\n"
        "    for (int l = l0; l < l0 + PDW_SOA_CHUNK; ++l) {\n"
        + kin + on + law(lambda src: src % 1) + second + "\n        }\n    }")


def _contact_body(fname, extra, code, fields, outs, void_p=True):
    """The batched contact stage's function around the lane loop's code (``void_p``: the code
    may not read p)."""
    store = "\n".join("            c[PDW_CONTACT_%s*PDW_SOA + l] = on ? %s : 0.0;"
                      % (f.upper(), o) for f, o in zip(fields, outs))
    return _function(
        "static void %s(int W, const double *restrict kin, const long long *restrict flags,\n"
        "    const double *restrict p%s, double *restrict contact)" % (fname, extra),
        ("    (void)p;\n" if void_p else "") +
        "    for (int i = 0; i < 2; ++i) {\n"
        "        const double *restrict ki = kin + i*PDW_NKIN*PDW_SOA;\n"
        "        double *restrict c = contact + i*PDW_NCONTACT*PDW_SOA;\n"
        "        const long long *restrict fl = flags + i*PDW_SOA;\n"
        "        for (int l0 = 0; l0 < W; l0 += PDW_SOA_CHUNK) {\n"
        "        #pragma omp simd\n"
        "        for (int l = l0; l < l0 + PDW_SOA_CHUNK; ++l) {\n"
        "            /* mask: a penetrating support foot (the scalar stage's branch) */\n"
        "            const long long on = (fl[l] != 0) & (ki[PDW_KIN_Y_D*PDW_SOA + l] < 0.0);\n"
        "            const double delta = -ki[PDW_KIN_Y_D*PDW_SOA + l];\n"
        "            const double deltad = -ki[PDW_KIN_V_Y*PDW_SOA + l];\n"
        "            const double v_t = ki[PDW_KIN_V_X*PDW_SOA + l];\n"
        "            const double xi = ki[PDW_KIN_XI*PDW_SOA + l];\n"
        "            const double v_in = ki[PDW_KIN_V_IN*PDW_SOA + l];\n"
        "            (void)delta; (void)deltad; (void)v_t; (void)xi; (void)v_in;\n"
        "            double %s;\n"
        "%s\n%s\n        }\n        }\n    }" % (", ".join(outs), code, store))


def _contact_function(fname, exprs, fields, soa, c_block):
    """A batched contact stage: the scalar stage's branch (a penetrating support foot) as a
    mask, every lane evaluating the law and keeping it only where its foot is one. The flags
    are 64-bit, as wide as the doubles: with int32 ones GCC vectorizes the lane loop at half
    the width on AVX-512."""
    outs = ["o_%s" % f.lower() for f in fields]
    # the parameters as locals loaded up front: the law's branches then hold no loads, and the
    # compiler turns them into selects (a branch with a load would need a masked load)
    used = set().union(*(e.free_symbols for e in exprs))
    pre = {s_: "pv_%s" % n for n, s_ in mdl.P.items() if s_ in used}
    loads = "".join("            const double %s = %s;\n" % (pre[s_], soa[s_])
                    for s_ in sorted(pre, key=lambda s_: pre[s_]))
    code, _ = c_block(exprs, outs, {**soa, **pre}, indent="            ")
    return _contact_body(fname, "", loads + code, fields, outs, void_p=False)


HEADER = """\
{banner}
/* Structure-of-arrays stages for the ensemble engine (derive/emit_batch.py, docs/ensemble.md):
 * element i of lane l at a[i*PDW_SOA + l]. Included by each instruction-set variant of the
 * lane loop (pdw/core/csrc/pdw_batch_soa.inc); every function is static. */
#ifndef PDW_BATCH_GEN_H
#define PDW_BATCH_GEN_H

#include <math.h>
#include <stddef.h>
#include "pdw_model.h"

/* derive/ input hash these stages were generated from (= PDW_INPUT_HASH of pdw_model.h) */
#define PDW_BATCH_INPUT_HASH "{hash}"

/* the stride of a structure-of-arrays row: room for the most lanes of a block (64), and 9
 * cache lines, not a power of two, so that the many rows a stage touches at the same lane
 * fall in different cache sets (a 512-byte stride thrashes an 8-way L1 in 8 sets) */
enum {{ PDW_SOA = 72 }};
/* lanes are computed in chunks of this many (the stages compute ceil(W/8)*8 lanes) */
enum {{ PDW_SOA_CHUNK = 8 }};

/* The batched stages of one kernel (NULL: none, run the scalar stages). */
typedef struct pdw_soa_kernel {{
    void (*kinematics)(int W, const double *x, const double *trig, const double *p,
                       const double *anchors, double *kin);
    void (*contact)(int W, const double *kin, const long long *flags, const double *p,
                    double *contact);
    /* the cdm lane loop's cdm_terms and update in one (PDW_SOA_CDM_UPDATE), and M[2][2],
     * M[3][3] alone into rows md */
    void (*cdm_update)(int W, double *x, double *u_prev, const double *trig, const double *p,
                       const double *contact, const double *hip, const double *kinv,
                       long long *armed, const long long *armed_next, long long *rare,
                       double idt2, double ih, double max_speed);
    void (*mdiag)(int W, const double *x, const double *trig, const double *p,
                  const double *contact, double *md);
    /* the right-hand side's and the Jacobian's (rodas4's lane loop) */
    void (*contact_partials)(int W, const double *kin, const long long *flags,
                             const double *p, double *contact);
    void (*dynamics)(int W, const double *x, const double *trig, const double *p,
                     const double *contact, double *M, double *f);
    void (*dynamics_jacobian)(int W, const double *x, const double *trig, const double *p,
                              const double *contact, const double *qdd, double *A);
    /* the cdm lane loop's kinematics, flag rules and contact stage in one (PDW_SOA_RULES):
     * contact_consts (once per walker) writes the law's parameter-only temporaries into nkc
     * rows kc, which kin_contact reads (same bits) */
    void (*contact_consts)(int W, const double *p, double *kc);
    void (*kin_contact)(int W, const double *x, const double *trig, const double *p,
                        const double *anchors, const double *kc, const long long *flags,
                        const long long *armed, const long long *upd, const double *depth,
                        long long *armed_next, long long *rare, double *contact);
    int nkc;
}} pdw_soa_kernel;

/* the most rows kc of any kernel */
enum {{ PDW_SOA_NKC = {nkc} }};

{body}
/* indexed like pdw_kernels[] */
static const pdw_soa_kernel pdw_soa_kernels[PDW_NKERNELS] = {{
{table}
}};

#endif /* PDW_BATCH_GEN_H */
"""


def header(banner, h, kernels, names_of, c_block, nforces):
    """The text of generated/pdw_batch_gen.h."""
    body, rows, nkc = [], [], 0
    for spec in kernels:
        if spec.normal != "hunt_crossley" or getattr(spec, "friction", "coulomb") != "coulomb":
            rows.append("    {NULL, NULL, NULL, NULL, NULL, NULL, NULL, NULL, NULL, 0},   /* %s */"
                        % spec.name)
            continue
        body.append(emit_kernel(spec, names_of(spec), c_block, nforces))
        rows.append("    {%s_kinematics, %s_contact, %s_cdm_update, %s_mdiag,\n"
                    "     %s_contact_partials, %s_dynamics, %s_dynamics_jacobian,\n"
                    "     %s_contact_consts, %s_kin_contact, %s_NKC},"
                    % (("pdw_soa_" + spec.name,) * 9 + (("PDW_SOA_" + spec.name).upper(),)))
        nkc = max(nkc, int(re.search(r"_NKC = (\d+)", body[-1]).group(1)))
    return HEADER.format(banner=banner, hash=h, body="\n".join(body), table="\n".join(rows),
                         nkc=nkc)
