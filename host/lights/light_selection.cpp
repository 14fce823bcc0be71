#include "lights/light_selection.h"

#include <algorithm>
#include <cstring>

#include "lights/discrete.h"

namespace mcrt {

LightSelectionData build_light_selection(LightSelection selection,
                                         const LightSelectionInputs& inputs) {
    LightSelectionData data;
    data.selection = selection;
    switch (selection) {
        case LightSelection::Uniform:
            break;
        case LightSelection::Power:
            data.cdf = build_cdf(inputs.powers);
            break;
        case LightSelection::Alias:
            data.alias = build_alias_table(inputs.powers);
            break;
        case LightSelection::Tree:
            data.tree =
                build_light_tree(inputs.lights, inputs.powers, 0, inputs.punctual_tree_items);
            break;
    }
    return data;
}

std::vector<uint32_t> light_selection_words(const LightSelectionData& data, uint32_t* tree_nodes) {
    *tree_nodes = 0;
    auto words = [](const auto& items) {
        std::vector<uint32_t> w(items.size() * sizeof(items[0]) / sizeof(uint32_t));
        if (!items.empty()) std::memcpy(w.data(), items.data(), w.size() * sizeof(uint32_t));
        return w;
    };
    switch (data.selection) {
        case LightSelection::Uniform:
            return {};
        case LightSelection::Power:
            return words(data.cdf);
        case LightSelection::Alias:
            return words(data.alias);
        case LightSelection::Tree:
            *tree_nodes = uint32_t(std::max<size_t>(data.tree.nodes.size(), 1));
            return light_tree_words(data.tree);
    }
    return {};
}

}  // namespace mcrt
