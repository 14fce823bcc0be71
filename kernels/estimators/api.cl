/* The public kernel API that every estimator is written against, built-in or a user's
 * --estimator-file (docs/ESTIMATORS.md is its reference): the sample stream (rng.cl), the
 * warps with their pdf twins (sampling.cl, frame.cl), the surface point and visibility
 * (scene.cl), the BSDF (bsdf.cl), the light strategies with their pdf twins
 * (light_sampling.cl), and below the MIS weight and the hand-over of a BSDF sample to the
 * path. */
#ifndef MCRT_API_CL
#define MCRT_API_CL

#include "bsdf.cl"
#include "frame.cl"
#include "light_sampling.cl"
#include "rng.cl"
#include "sampling.cl"
#include "scene.cl"
#include "shared_types.h"

/* What an estimator hands the path at a vertex: a BSDF sample it drew there and what its ray
 * found, as pbrt-v4's path integrator carries its BSDF sample and pdf to the next vertex. */
struct PathContinuation {
    BsdfSample bs;
    SurfacePoint seen; /* the surface its ray found, when `found` */
    bool found;
    bool given; /* an estimator handed a sample at this vertex (the path clears it) */
};

/* Traces the ray of bs, a sample of bsdf_sample at sp, like trace_from, and hands both to the
 * path: at a vertex that the path goes on from, it continues along this sample (throughput
 * f·cosθ/pdf, the surface found) instead of drawing and tracing one of its own (path.cl). The
 * path's own draw is bsdf_sample of the vertex's DIM_DIRECTION numbers, so an estimator that
 * hands over that sample leaves the image unchanged and saves the path a ray. Counts the ray. */
inline bool trace_bsdf_sample(const SceneView* scene, const SurfacePoint* sp,
                              const BsdfSample* bs, uint* rays, SurfacePoint* seen) {
    bool found = trace_from(scene, sp, bs->wi, rays, seen);
    PathContinuation* c = scene->continuation;
    if (c) {
        c->bs = *bs;
        c->found = found;
        if (found) c->seen = *seen;
        c->given = true;
    }
    return found;
}

/* Weight of strategy a against b, both densities in solid angle (Veach 1997, sec. 9.2): balance
 * (-D MIS_BALANCE) or power with β = 2 (-D MIS_POWER), written as ratios so large densities
 * cannot overflow. The host defines the chosen one for the estimators that weigh strategies
 * (uses mis-heuristic), balance for the others. */
#if !defined(MIS_POWER) && !defined(MIS_BALANCE)
#error "no MIS heuristic: the host defines MIS_BALANCE or MIS_POWER (host/render/variants.cpp)"
#endif
inline float mis_weight(float pdf_a, float pdf_b) {
    if (!(pdf_b > 0.0f)) return 1.0f;
    float r = pdf_b / pdf_a;
#if defined(MIS_POWER)
    return 1.0f / (1.0f + r * r);
#else
    return 1.0f / (1.0f + r);
#endif
}

/* MIS weight of light sample ls against a BSDF strategy of density pdf_bsdf (solid angle) for
 * its direction: mis_weight(light_sample_pdf_w(ls), pdf_bsdf), and 1 for a delta light, which
 * the BSDF strategy can never find (PBRT 4th ed. 13.4.2, delta lights). */
inline float light_sample_mis_weight(const LightSample* ls, float pdf_bsdf) {
    if (light_sample_is_delta(ls)) return 1.0f;
    return mis_weight(light_sample_pdf_w(ls), pdf_bsdf);
}

#endif
