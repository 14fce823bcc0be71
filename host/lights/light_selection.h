// The data of one light selection, built from the lights' powers and laid out as the kernels
// read it (RENDER_ARG_LIGHT_SELECTION; kernels/lights/select_*.cl): pbrt-v4 gives each light
// sampler one unit that owns its data and its sample/pmf pair, and so does each selection here,
// a case of the two functions below beside its kernel file.
#pragma once

#include <cstdint>
#include <vector>

#include "lights/light_tree.h"
#include "render/variants.h"
#include "shared_types.h"

namespace mcrt {

// What every selection is built from: the area lights, their powers and then the punctual
// lights' (one per light the selection chooses among), and the punctual lights' tree bounds.
struct LightSelectionInputs {
    const std::vector<gpu::Light>& lights;
    const std::vector<double>& powers;
    const std::vector<LightTreeItem>& punctual_tree_items;
};

// One selection's data, only that of `selection` built: power's CDF (lights + 1 entries, PBRT
// 3rd ed. 13.3.1), alias's table of the same distribution, or the tree (lights/light_tree.h);
// uniform has none.
struct LightSelectionData {
    LightSelection selection = LightSelection::Power;
    std::vector<float> cdf;
    std::vector<gpu::AliasEntry> alias;
    LightTree tree;
};

// Builds the data of `selection`.
LightSelectionData build_light_selection(LightSelection selection,
                                         const LightSelectionInputs& inputs);

// The selection's buffer as the kernels read it, in 32-bit words; `tree_nodes` the nodes at its
// head for the tree, else 0.
std::vector<uint32_t> light_selection_words(const LightSelectionData& data, uint32_t* tree_nodes);

}  // namespace mcrt
