/* Choosing an emissive triangle and a point or direction on it. */
#ifndef MCRT_LIGHTS_CL
#define MCRT_LIGHTS_CL

#include "discrete.cl"
#include "light_tree.cl"
#include "sampling.cl"

/* Lights and their selection distributions: light_cdf (light_count + 1 entries) and alias
 * (light_count entries) both follow emitted power; the light tree (light_tree.cl) weighs power
 * by distance and orientation at the shading point. Zero-power lights are never selected. */
typedef struct {
    global const Light* lights;
    global const float* light_cdf;
    global const AliasEntry* alias;
    global const LightTreeNode* tree;
    uint light_count;
} LightSet;

/* Selects a light for the shading point p with unit normal n (the side light must arrive
 * from) from u (-D LIGHT_SELECT_UNIFORM, LIGHT_SELECT_POWER, LIGHT_SELECT_ALIAS or
 * LIGHT_SELECT_TREE; only the tree reads p and n), refined below the 2^-24 grid by u_fine
 * (discrete.cl); the choice's u_remap is uniform again, for the point on the light.
 * light_count must be > 0. pmf 0 (the tree only): no light can reach p, nothing was chosen. */
inline DiscreteSample select_light(const LightSet* ls, float3 p, float3 n, float u,
                                   float u_fine) {
#if defined(LIGHT_SELECT_UNIFORM)
    return sample_discrete_uniform(ls->light_count, u, u_fine);
#elif defined(LIGHT_SELECT_ALIAS)
    return sample_discrete_alias(ls->alias, ls->light_count, u, u_fine);
#elif defined(LIGHT_SELECT_TREE)
    return sample_light_tree(ls->tree, p, n, u, u_fine);
#else
    return sample_discrete_cdf(ls->light_cdf, ls->light_count, u, u_fine);
#endif
}

/* Probability that select_light at (p, n) returns light i. */
inline float light_pmf(const LightSet* ls, float3 p, float3 n, uint i) {
#if defined(LIGHT_SELECT_UNIFORM)
    return 1.0f / (float)ls->light_count;
#elif defined(LIGHT_SELECT_ALIAS)
    return discrete_alias_pmf(ls->alias, i);
#elif defined(LIGHT_SELECT_TREE)
    global const Light* light = ls->lights + i;
    return light_tree_pmf(ls->tree, as_uint(light->Le.w), as_uint(light->p2.w), p, n);
#else
    return discrete_cdf_pmf(ls->light_cdf, i);
#endif
}

inline bool light_double_sided(const Light* light) {
    return (as_uint(light->p1.w) & MATERIAL_DOUBLE_SIDED) != 0u;
}

inline float light_area(const Light* light) { return light->p0.w; }

/* Unit front-face normal (counter-clockwise winding). */
inline float3 light_normal(const Light* light) {
    return normalize(cross(light->p1.xyz - light->p0.xyz, light->p2.xyz - light->p0.xyz));
}

typedef struct {
    float3 p;       /* point on the light */
    float3 p_error; /* per-component bound on p's distance from the light's plane */
    float pdf_a;
} LightPoint;

/* Uniform point on the light's triangle; density with respect to area. */
inline LightPoint sample_light_point(const Light* light, float2 u) {
    float2 b = sample_triangle_uniform(u);
    float3 p0 = light->p0.xyz;
    LightPoint lp;
    float3 b1_e1 = b.x * (light->p1.xyz - p0), b2_e2 = b.y * (light->p2.xyz - p0);
    lp.p = p0 + b1_e1 + b2_e2;
    lp.p_error = interpolation_error(p0, b1_e1, b2_e2);
    lp.pdf_a = sample_triangle_uniform_pdf_a(light_area(light));
    return lp;
}

/* Cosine at the light between its normal and the direction wi from the receiver toward it:
 * positive when the receiver sees an emitting face, else 0. */
inline float light_emitting_cosine(const Light* light, float3 n_light, float3 wi) {
    float c = -dot(n_light, wi);
    if (light_double_sided(light)) c = fabs(c);
    return max(c, 0.0f);
}

#endif
