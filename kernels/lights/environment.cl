/* Latitude-longitude environment maps on the device, the twins of host/scene/environment_map.h:
 * Mitsuba 3's envmap mapping for +Y up (u = atan2(x, −z)/2π, v = acos(y)/π, row 0 at the
 * zenith), nearest texels, and directions drawn by the texel CDF with their solid-angle pdf.
 * Only IEEE-754 basic operations and exact_math.cl's functions, so that every OpenCL
 * implementation gives the same bits (the built-in atan2, acos, sin, cos and cospi differ). */
#ifndef MCRT_ENVIRONMENT_CL
#define MCRT_ENVIRONMENT_CL

#include "discrete.cl"
#include "exact_math.cl"
#include "shared_types.h"

typedef struct {
    global const float* rgb; /* 3 per texel, row-major, row 0 at the zenith */
    global const float* cdf; /* width·height + 1 entries on the 2^-24 grid (build_cdf) */
    uint width, height;
    float cos_rot, sin_rot; /* the map's turn about +Y, counter-clockwise seen from above */
} EnvironmentMapView;

/* Index row·width + column of the texel that holds world direction d (unit). */
inline uint environment_texel(const EnvironmentMapView* env, float3 d) {
    /* The map turned by a shows at world d what it holds at R_y(−a) d. */
    float x = d.x * env->cos_rot - d.z * env->sin_rot;
    float z = d.x * env->sin_rot + d.z * env->cos_rot;
    float u = exact_atan2(x, -z) * (0.5f * M_1_PI_F);
    if (u < 0.0f) u += 1.0f;
    /* acos(y) = atan2(√((1 − y)(1 + y)), y), y clamped to [−1, 1] */
    float y = clamp(d.y, -1.0f, 1.0f);
    float v = exact_atan2(sqrt((1.0f - y) * (1.0f + y)), y) * M_1_PI_F;
    uint i = min((uint)(u * (float)env->width), env->width - 1u);
    uint j = min((uint)(v * (float)env->height), env->height - 1u);
    return j * env->width + i;
}

/* Solid angle of a texel of row j: (2π/W)(cos θ_j − cos θ_{j+1}), θ_j = πj/H. */
inline float environment_texel_solid_angle(const EnvironmentMapView* env, uint j) {
    float h = (float)env->height;
    return (2.0f * M_PI_F / (float)env->width) *
           (exact_cospi((float)j / h) - exact_cospi((float)(j + 1u) / h));
}

/* Radiance arriving from direction d (unit, world). */
inline float3 environment_map_radiance(const EnvironmentMapView* env, float3 d) {
    uint k = environment_texel(env, d);
    return (float3)(env->rgb[3u * k], env->rgb[3u * k + 1u], env->rgb[3u * k + 2u]);
}

typedef struct {
    float3 wi;   /* world direction */
    float pdf_w; /* with respect to solid angle: pmf of the texel / its solid angle */
    uint texel;
} EnvironmentSample;

/* The direction of texel choice ds: u uniform in φ and cos θ within the texel, so uniform in
 * solid angle over it (PBRT 4th ed. §12.5.2, with nearest texels). */
inline EnvironmentSample environment_texel_direction(const EnvironmentMapView* env,
                                                     DiscreteSample ds, float2 u) {
    uint i = ds.index % env->width, j = ds.index / env->width;
    /* φ = 2π(i + u.x)/W, its sine and cosine as sinpi and cospi of φ/π */
    float cos_phi;
    float sin_phi = exact_sincospi(2.0f * ((float)i + u.x) / (float)env->width, &cos_phi);
    float cos_top = exact_cospi((float)j / (float)env->height);
    float cos_bottom = exact_cospi((float)(j + 1u) / (float)env->height);
    float cos_theta = exact_mix(cos_top, cos_bottom, u.y);
    float sin_theta = sqrt(max(0.0f, 1.0f - cos_theta * cos_theta));
    float xm = sin_theta * sin_phi, zm = -sin_theta * cos_phi;
    EnvironmentSample s;
    s.wi = (float3)(xm * env->cos_rot + zm * env->sin_rot, cos_theta,
                    -xm * env->sin_rot + zm * env->cos_rot);
    s.texel = ds.index;
    s.pdf_w = ds.pmf / environment_texel_solid_angle(env, j);
    return s;
}

/* u_select (with u_fine) chooses the texel by the CDF; u places the direction within it. */
inline EnvironmentSample sample_environment_map(const EnvironmentMapView* env, float u_select,
                                                float u_fine, float2 u) {
    DiscreteSample ds =
        sample_discrete_cdf(env->cdf, env->width * env->height, u_select, u_fine);
    return environment_texel_direction(env, ds, u);
}

/* The same from three numbers, as the light strategies have them: the texel choice's remapped
 * number (uniform again, discrete.cl) places φ and v places cos θ. */
inline EnvironmentSample sample_environment_map_reusing(const EnvironmentMapView* env,
                                                        float u_select, float u_fine, float v) {
    DiscreteSample ds =
        sample_discrete_cdf(env->cdf, env->width * env->height, u_select, u_fine);
    return environment_texel_direction(env, ds, (float2)(ds.u_remap, v));
}

/* The twin: density with respect to solid angle of drawing direction d (unit, world). */
inline float environment_map_pdf_w(const EnvironmentMapView* env, float3 d) {
    uint k = environment_texel(env, d);
    return (env->cdf[k + 1u] - env->cdf[k]) / environment_texel_solid_angle(env, k / env->width);
}

#endif
