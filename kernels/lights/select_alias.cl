/* Light selection in proportion to emitted power by an alias table (Walker 1977; PBRT 4th ed.
 * A.1.4): the distribution of select_power.cl in constant time. -D LIGHT_SELECT_ALIAS; the table
 * is built by host/lights/. */
#ifndef MCRT_SELECT_ALIAS_CL
#define MCRT_SELECT_ALIAS_CL

#include "discrete.cl"

typedef struct {
    global const AliasEntry* alias; /* light count entries */
} LightSelectionView;

inline LightSelectionView light_selection_view(global const uint* selection, uint tree_nodes) {
    LightSelectionView view;
    view.alias = (global const AliasEntry*)selection;
    return view;
}

/* One of `count` lights from u, refined by u_fine (discrete.cl); p and n are not read. */
inline DiscreteSample select_light_in(const LightSelectionView* view, uint count, float3 p,
                                      float3 n, float u, float u_fine) {
    return sample_discrete_alias(view->alias, count, u, u_fine);
}

/* Probability that select_light_in returns light i. */
inline float light_selection_pmf(const LightSelectionView* view, uint count, float3 p, float3 n,
                                 uint i) {
    return discrete_alias_pmf(view->alias, i);
}

#endif
