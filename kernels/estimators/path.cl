/* Paths: the chosen estimator as next-event estimation at every vertex, the path going on by
 * sampling the BSDF (PBRT 3rd ed. 14.5; Veach 1997, sec. 10.4). One work-item traces one whole
 * path; its random numbers are those of the vertex it is at (rng.cl, stream_dimension). */
#ifndef MCRT_PATH_CL
#define MCRT_PATH_CL

#include "api.cl"

#if !defined(MCRT_ESTIMATE)
#error "no estimator selected: the host defines MCRT_ESTIMATE (host/render/variants.cpp)"
#endif

/* Russian roulette keeps a path with probability min(max channel of its throughput, 0.95), as
 * Mitsuba 3's path integrator does, and divides the survivors by it: unbiased (PBRT 3rd ed.
 * 13.7), and even a bright path ends eventually. */
#define MCRT_RR_MAX_SURVIVAL 0.95f

inline float max_component(float3 v) { return fmax(v.x, fmax(v.y, v.z)); }

/* What a path did, for the stats: surface vertices it reached, and whether roulette ended it. */
typedef struct {
    uint rays;
    uint vertices;
    bool roulette;
} PathRecord;

/* The stochastic-transparency key of the stream's vertex (textured builds): its DIM_ALPHA
 * number with the pixel and the sample, so that every sample decides blended surfaces anew. */
inline void set_alpha_key(const SceneView* scene, const SampleStream* stream) {
#if defined(MCRT_TEXTURES)
    *scene->alpha_key = alpha_hash(as_uint(sample_1d(stream, DIM_ALPHA)) ^
                                          alpha_hash(stream->pixel ^ alpha_hash(stream->index)));
#endif
}

#if defined(MCRT_TRANSMISSION)
/* The transmittance of the segment of length t that sample bs starts at sp: Beer–Lambert
 * (dielectric.cl) where it runs inside sp's volume — transmitted into it from the outside (front)
 * or reflected from the inside (back) — else 1. A volume's own surfaces bound it: what another
 * surface inside it sends is not attenuated (no nested media). */
inline float3 segment_transmittance(const SurfacePoint* sp, const BsdfSample* bs, float t) {
    if ((sp->material.flags & MATERIAL_VOLUME) == 0u) return (float3)(1.0f);
    bool transmitted = (bs->lobe & BSDF_LOBE_TRANSMITTED) != 0u;
    if (transmitted != sp->front) return (float3)(1.0f);
    return beer_lambert(sp->material.attenuation.xyz, t);
}
#endif

/* Radiance arriving along camera ray r after at most max_depth reflections: L_e at the first hit,
 * plus at each vertex k < max_depth the throughput times the estimator's estimate of the light
 * reflected there directly (its own strategies; emitters that the continuation later finds are
 * not counted again). The continuation is the BSDF sample the estimator handed over
 * (trace_bsdf_sample, api.cl: the BSDF and MIS estimators hand theirs, as pbrt's path tracer
 * shares one sample), else the path's own draw with the vertex's DIM_DIRECTION numbers. A camera
 * ray leaving the scene sees black or the sky light; with an ambient estimator, which has no
 * path (-D MCRT_AMBIENT_ESTIMATOR), the sky (DESIGN.md "Radiometric contract"). With transmissive
 * materials (-D MCRT_TRANSMISSION) the path also adds what a continuation that no light strategy
 * could have drawn (bsdf_sample_is_direct false) finds, and attenuates segments inside volumes. */
inline float3 path_radiance(const SceneView* scene, const Ray* r, SampleStream* stream,
                            uint max_depth, uint rr_depth, PathRecord* record) {
    PathContinuation* given = scene->continuation; /* 0 for direct lighting */
    record->rays += 1u;
    stream->vertex = 0u;
    set_alpha_key(scene, stream);
    AlphaTest at = ray_alpha_test(scene, r);
    Hit hit = bvh_closest_hit(scene->nodes, scene->packets, r, MAXFLOAT, MCRT_NO_HIT, &at);
#if defined(MCRT_AMBIENT_ESTIMATOR) && !defined(MCRT_ENVIRONMENT_MAP)
    if (hit.lane == MCRT_NO_HIT) return scene->env.sky;
#else
    if (hit.lane == MCRT_NO_HIT) return environment_radiance(scene, normalize(r->dir));
#endif
    SurfacePoint sp = surface_point(scene, r, &hit);
    record->vertices = 1u;
    float3 L = emitted_radiance(&sp);
    float3 beta = (float3)(1.0f); /* throughput: f·cosθ/pdf along the path so far */
    for (uint k = 0u; k < max_depth;) {
        /* Direct light at vertex k, by the estimator's strategies. */
        stream->vertex = k;
        set_alpha_key(scene, stream);
        if (given) given->given = false;
        L += beta * MCRT_ESTIMATE(scene, &sp, stream, &record->rays);
        if (++k == max_depth) break;

        /* Continue by BSDF sampling: the estimator's sample, or the path's own. */
        bool handed = given && given->given;
        BsdfSample bs = handed ? given->bs : bsdf_sample(&sp, sample_2d(stream, DIM_DIRECTION));
        if (!(bs.pdf_w > 0.0f) || bs.cos_theta <= 0.0f) break;
        beta *= bs.f * (bs.cos_theta / bs.pdf_w);
        if (!(max_component(beta) > 0.0f)) break;

        /* Russian roulette before vertex k, with that vertex's number. */
        stream->vertex = k;
        if (k >= rr_depth) {
            float survive = fmin(max_component(beta), MCRT_RR_MAX_SURVIVAL);
            if (!(sample_1d(stream, DIM_ROULETTE) < survive)) {
                record->roulette = true;
                break;
            }
            beta /= survive;
        }

        SurfacePoint next;
#if defined(MCRT_TRANSMISSION)
        bool found = handed ? given->found : trace_from(scene, &sp, bs.wi, &record->rays, &next);
        if (handed && found) next = given->seen;
        /* Beer–Lambert along a segment inside a volume; then the light that this sample finds
         * where the estimators' light strategies could not look (through a surface, or along a
         * delta): the emitter it hits, or the sky it leaves to. */
        beta *= segment_transmittance(&sp, &bs, found ? length(next.p - sp.p) : MAXFLOAT);
        if (!bsdf_sample_is_direct(&bs))
            L += beta * (found ? emitted_radiance(&next) : environment_radiance(scene, bs.wi));
        if (!found) break;
#else
        if (handed) {
            if (!given->found) break;
            next = given->seen;
        } else if (!trace_from(scene, &sp, bs.wi, &record->rays, &next)) {
            break;
        }
#endif
        sp = next;
        record->vertices += 1u;
    }
    return L;
}

/* The record in the 32 bits that render writes beside a sample's radiance (reduce_chunks reads
 * them): rays in bits 0-19 (saturated), vertices in 20-30 (at most MCRT_MAX_PATH_DEPTH + 1 < 2^11),
 * roulette in bit 31. */
#define PATH_RECORD_MAX_RAYS 0xfffffu
inline uint pack_path_record(const PathRecord* record) {
    return min(record->rays, PATH_RECORD_MAX_RAYS) | (record->vertices << 20) |
           (record->roulette ? 0x80000000u : 0u);
}
inline uint path_record_rays(uint packed) { return packed & PATH_RECORD_MAX_RAYS; }
inline uint path_record_vertices(uint packed) { return (packed >> 20) & 0x7ffu; }
inline uint path_record_roulette(uint packed) { return packed >> 31; }

#endif
