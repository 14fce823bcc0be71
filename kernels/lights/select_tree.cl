/* Light selection by the light tree (light_tree.cl): power weighed by distance and orientation
 * at the shading point (Conty Estevez & Kulla 2018; pbrt-v4's BVHLightSampler).
 * -D LIGHT_SELECT_TREE; the tree and the lights' paths are built by host/lights/. */
#ifndef MCRT_SELECT_TREE_CL
#define MCRT_SELECT_TREE_CL

#include "discrete.cl"
#include "light_tree.cl"

typedef struct {
    global const LightTreeNode* tree;
    global const LightTreePath* paths; /* one per light, after the tree's nodes */
    global const Light* lights;        /* the area lights, which the walk prefetches */
    uint light_count;
} LightSelectionView;

/* The buffer holds the tree's `tree_nodes` nodes, then the lights' paths. */
inline LightSelectionView light_selection_view(global const uint* selection, uint tree_nodes) {
    LightSelectionView view;
    view.tree = (global const LightTreeNode*)selection;
    view.paths = (global const LightTreePath*)(view.tree + tree_nodes);
    view.lights = 0;
    view.light_count = 0u;
    return view;
}

/* A light for the shading point p with unit normal n from u, refined by u_fine (discrete.cl);
 * pmf 0: no light can reach p, nothing was chosen. */
inline DiscreteSample select_light_in(const LightSelectionView* view, uint count, float3 p,
                                      float3 n, float u, float u_fine) {
    return sample_light_tree(view->tree, view->lights, view->light_count, p, n, u, u_fine);
}

/* Probability that select_light_in at (p, n) returns light i: its stored path walked with the
 * arithmetic of the choice. */
inline float light_selection_pmf(const LightSelectionView* view, uint count, float3 p, float3 n,
                                 uint i) {
    LightTreePath path = view->paths[i];
    return light_tree_pmf(view->tree, path.bits, path.length, p, n);
}

#endif
