/* Choosing an emissive triangle and a point or direction on it. */
#ifndef MCRT_LIGHTS_CL
#define MCRT_LIGHTS_CL

/* What the selection files include, included here first: the host expands each file once, at its
 * first #include, whether or not an #if around it holds (host/cl/program.cpp). */
#include "discrete.cl"
#include "light_tree.cl"
#include "sampling.cl"

/* The light selection the render was built for, one file each in kernels/lights/ (the host's
 * table of variants, host/render/variants.cpp; its data built by host/lights/): each defines
 * LightSelectionView (its view of the selection buffer), light_selection_view, select_light_in
 * and its twin light_selection_pmf. Zero-power lights are never selected. */
#if defined(LIGHT_SELECT_UNIFORM)
#include "select_uniform.cl"
#elif defined(LIGHT_SELECT_POWER)
#include "select_power.cl"
#elif defined(LIGHT_SELECT_ALIAS)
#include "select_alias.cl"
#elif defined(LIGHT_SELECT_TREE)
#include "select_tree.cl"
#else
#error "no light selection: the host defines one LIGHT_SELECT_* (host/render/variants.cpp)"
#endif

/* The lights and the data of the light selection. */
typedef struct {
    global const Light* lights;
    LightSelectionView selection;
    uint light_count; /* area lights: lights[0, light_count) */
#if defined(MCRT_PUNCTUAL)
    /* The punctual lights (shared_types.h, PunctualGpu), the selection's lights light_count + i:
     * after the area lights in its CDF, alias table and tree. */
    global const PunctualGpu* punctual;
    uint punctual_count;
#endif
} LightSet;

/* How many lights the selection chooses among: the area lights, then the punctual ones. */
inline uint light_selection_count(const LightSet* ls) {
#if defined(MCRT_PUNCTUAL)
    return ls->light_count + ls->punctual_count;
#else
    return ls->light_count;
#endif
}

/* The lights and the selection's view of its buffer (shared_types.h, RENDER_ARG_LIGHT_SELECTION:
 * for the tree, its `tree_nodes` nodes, then the lights' paths). */
inline LightSet light_set(global const Light* lights, uint light_count,
                          global const uint* selection, uint tree_nodes) {
    LightSet ls;
    ls.lights = lights;
    ls.light_count = light_count;
    ls.selection = light_selection_view(selection, tree_nodes);
#if defined(LIGHT_SELECT_TREE)
    ls.selection.lights = lights; /* for the walk's prefetch of the chosen light */
    ls.selection.light_count = light_count;
#endif
    return ls;
}

/* Selects a light for the shading point p with unit normal n (the side light must arrive
 * from) from u (only the tree reads p and n), refined below the 2^-24 grid by u_fine
 * (discrete.cl); the choice's u_remap is uniform again, for the point on the light.
 * light_selection_count must be > 0. pmf 0 (the tree only): no light can reach p, nothing was chosen. */
inline DiscreteSample select_light(const LightSet* ls, float3 p, float3 n, float u,
                                   float u_fine) {
    return select_light_in(&ls->selection, light_selection_count(ls), p, n, u, u_fine);
}

/* Probability that select_light at (p, n) returns light i. */
inline float light_pmf(const LightSet* ls, float3 p, float3 n, uint i) {
    return light_selection_pmf(&ls->selection, light_selection_count(ls), p, n, i);
}

inline bool light_double_sided(const Light* light) {
    return (light->flags & MATERIAL_DOUBLE_SIDED) != 0u;
}

inline float light_area(const Light* light) { return light->area; }

/* Unit front-face normal (counter-clockwise winding). */
inline float3 light_normal(const Light* light) {
    return normalize(cross(light->p1.xyz - light->p0.xyz, light->p2.xyz - light->p0.xyz));
}

typedef struct {
    float3 p;       /* point on the light */
    float3 p_error; /* per-component bound on p's distance from the light's plane */
    float2 b;       /* its barycentrics of vertices 1 and 2 */
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
    lp.b = b;
    lp.pdf_a = sample_triangle_uniform_pdf_a(light_area(light));
    return lp;
}

/* Barycentrics (of vertices 1 and 2) of a point y in the light's plane, clamped to the
 * triangle: where a direction sampled in its spherical triangle meets it. */
inline float2 light_barycentrics(const Light* light, float3 y) {
    float3 e1 = light->p1.xyz - light->p0.xyz, e2 = light->p2.xyz - light->p0.xyz;
    float3 v = y - light->p0.xyz;
    float d11 = dot(e1, e1), d12 = dot(e1, e2), d22 = dot(e2, e2);
    float dv1 = dot(v, e1), dv2 = dot(v, e2);
    float denom = d11 * d22 - d12 * d12;
    if (!(denom > 0.0f)) return (float2)(0.0f);
    float2 b = (float2)(d22 * dv1 - d12 * dv2, d11 * dv2 - d12 * dv1) / denom;
    b = clamp(b, 0.0f, 1.0f);
    float s = b.x + b.y;
    return s > 1.0f ? b / s : b;
}

/* Cosine at the light between its normal and the direction wi from the receiver toward it:
 * positive when the receiver sees an emitting face, else 0. */
inline float light_emitting_cosine(const Light* light, float3 n_light, float3 wi) {
    float c = -dot(n_light, wi);
    if (light_double_sided(light)) c = fabs(c);
    return max(c, 0.0f);
}

#endif
