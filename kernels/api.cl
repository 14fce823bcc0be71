/* The public kernel API that every estimator is written against, built-in or a user's
 * --estimator-file (docs/ESTIMATORS.md is its reference): the sample stream (rng.cl), the
 * warps with their pdf twins (sampling.cl, frame.cl), the surface point and visibility
 * (scene.cl), the BSDF (bsdf.cl), the light strategies with their pdf twins
 * (light_sampling.cl) and the MIS weight below. */
#ifndef MCRT_API_CL
#define MCRT_API_CL

#include "bsdf.cl"
#include "frame.cl"
#include "light_sampling.cl"
#include "rng.cl"
#include "sampling.cl"
#include "scene.cl"
#include "shared_types.h"

/* Weight of strategy a against b, both densities in solid angle (Veach 1997, sec. 9.2): balance,
 * or power with β = 2 (-D MIS_POWER, `--mis-heuristic power`), written as ratios so large
 * densities cannot overflow. */
inline float mis_weight(float pdf_a, float pdf_b) {
    if (!(pdf_b > 0.0f)) return 1.0f;
    float r = pdf_b / pdf_a;
#if defined(MIS_POWER)
    return 1.0f / (1.0f + r * r);
#else
    return 1.0f / (1.0f + r);
#endif
}

#endif
