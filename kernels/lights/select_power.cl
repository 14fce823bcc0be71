/* Light selection in proportion to emitted power by inverting a CDF (PBRT 3rd ed. 13.3.1;
 * pbrt-v4's PowerLightSampler). -D LIGHT_SELECT_POWER; the CDF is built by host/lights/. */
#ifndef MCRT_SELECT_POWER_CL
#define MCRT_SELECT_POWER_CL

#include "discrete.cl"

typedef struct {
    global const float* light_cdf; /* light count + 1 entries */
} LightSelectionView;

inline LightSelectionView light_selection_view(global const uint* selection, uint tree_nodes) {
    LightSelectionView view;
    view.light_cdf = (global const float*)selection;
    return view;
}

/* One of `count` lights from u, refined by u_fine (discrete.cl); p and n are not read. */
inline DiscreteSample select_light_in(const LightSelectionView* view, uint count, float3 p,
                                      float3 n, float u, float u_fine) {
    return sample_discrete_cdf(view->light_cdf, count, u, u_fine);
}

/* Probability that select_light_in returns light i. */
inline float light_selection_pmf(const LightSelectionView* view, uint count, float3 p, float3 n,
                                 uint i) {
    return discrete_cdf_pmf(view->light_cdf, i);
}

#endif
