/* The cost of choosing a light (bench/light_tree_bench.cpp): each work-item chooses one light
 * for one shading point by the method of the bench, and writes what it chose, so that nothing
 * is optimized away. Global size 1D; each entry checks its bound. */
#include "discrete.cl"
#include "light_tree.cl"
#include "rng.cl"
#include "shared_types.h"

/* Reads the CDF (method 0), the alias table (1), nothing (2, uniform) or the tree (3) of n
 * lights; writes out[g] = pmf of the light chosen for point g % points (p, normal) with u and
 * u_fine hashed from (g, seed), for g < count. */
kernel void light_select_bench(uint method, global const float* cdf, global const AliasEntry* alias,
                               global const LightTreeNode* tree, uint n, uint points,
                               global const float4* p, global const float4* normal, uint count,
                               uint seed, global float* out) {
    uint g = (uint)get_global_id(0);
    if (g >= count) return;
    uint4 h = pcg4d((uint4)(g, seed, 0xBE7Cu, 0u));
    float u = uint_to_unit_float(h.x), u_fine = uint_to_unit_float(h.y);
    uint k = g % points;
    DiscreteSample s = method == 0u   ? sample_discrete_cdf(cdf, n, u, u_fine)
                       : method == 1u ? sample_discrete_alias(alias, n, u, u_fine)
                       : method == 2u ? sample_discrete_uniform(n, u, u_fine)
                                      : sample_light_tree(tree, 0, 0u, p[k].xyz, normal[k].xyz, u, u_fine);
    out[g] = s.pmf + (float)s.index * 0x1.0p-60f;
}
