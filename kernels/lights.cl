/* Choosing an emissive triangle and a point on it. */
#ifndef MCRT_LIGHTS_CL
#define MCRT_LIGHTS_CL

#include "sampling.cl"

/* Lights and their selection distribution. light_cdf has light_count + 1 entries, cdf[0] = 0,
 * cdf[light_count] = 1; zero-power lights have empty intervals and are never selected. */
typedef struct {
    global const Light* lights;
    global const float* light_cdf;
    uint light_count;
} LightSet;

typedef struct {
    uint index;
    float pmf;
} LightChoice;

/* Selects a light with probability pmf; light_count must be > 0. */
inline LightChoice select_light(const LightSet* ls, float u) {
    LightChoice c;
#if defined(LIGHT_SELECT_UNIFORM)
    c.index = min((uint)(u * (float)ls->light_count), ls->light_count - 1u);
    c.pmf = 1.0f / (float)ls->light_count;
#else
    /* CDF inversion by binary search (PBRT 3rd ed. 13.3.1): the last i with cdf[i] <= u, whose
     * interval [cdf[i], cdf[i+1]) contains u and so is not empty. */
    uint lo = 0u, hi = ls->light_count;
    while (hi - lo > 1u) {
        uint mid = (lo + hi) / 2u;
        if (ls->light_cdf[mid] <= u)
            lo = mid;
        else
            hi = mid;
    }
    c.index = lo;
    c.pmf = ls->light_cdf[lo + 1u] - ls->light_cdf[lo];
#endif
    return c;
}

typedef struct {
    float3 p;  /* point on the light */
    float3 n;  /* unit front-face normal (counter-clockwise winding) */
    float pdf_a;
} LightPoint;

/* Uniform point on the light's triangle; density with respect to area. */
inline LightPoint sample_light_point(const Light* light, float2 u) {
    float2 b = sample_triangle_uniform(u);
    float3 p0 = light->p0.xyz, e1 = light->p1.xyz - p0, e2 = light->p2.xyz - p0;
    LightPoint lp;
    lp.p = p0 + b.x * e1 + b.y * e2;
    lp.n = normalize(cross(e1, e2));
    lp.pdf_a = sample_triangle_uniform_pdf_a(light->p0.w);
    return lp;
}

inline bool light_double_sided(const Light* light) {
    return (as_uint(light->p1.w) & MATERIAL_DOUBLE_SIDED) != 0u;
}

#endif
