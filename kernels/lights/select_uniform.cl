/* Uniform light selection: every light with probability 1/n (pbrt-v4's UniformLightSampler).
 * One of the light selections lights.cl chooses from (-D LIGHT_SELECT_UNIFORM). */
#ifndef MCRT_SELECT_UNIFORM_CL
#define MCRT_SELECT_UNIFORM_CL

#include "discrete.cl"

/* Uniform selection has no data: its buffer is one unread word (C has no empty struct). */
typedef struct {
    uint unused;
} LightSelectionView;

inline LightSelectionView light_selection_view(global const uint* selection, uint tree_nodes) {
    LightSelectionView view;
    view.unused = 0u;
    return view;
}

/* One of `count` lights from u, refined by u_fine (discrete.cl); p and n are not read. */
inline DiscreteSample select_light_in(const LightSelectionView* view, uint count, float3 p,
                                      float3 n, float u, float u_fine) {
    return sample_discrete_uniform(count, u, u_fine);
}

/* Probability that select_light_in returns light i. */
inline float light_selection_pmf(const LightSelectionView* view, uint count, float3 p, float3 n,
                                 uint i) {
    return 1.0f / (float)count;
}

#endif
