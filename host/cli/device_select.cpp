#include "cli/device_select.h"

#include <set>

#include "cl/no_device.h"
#include "common/error.h"

namespace mcrt {

std::vector<DeviceInfo> select_devices(const std::vector<std::string>& specs,
                                       const std::function<void(const std::string&)>& warn) {
    std::vector<DeviceInfo> all = enumerate_devices(warn);
    if (all.empty()) throw RuntimeError(no_device_message());
    if (specs.empty()) return {all.front()};
    std::set<int> chosen;
    for (const std::string& spec : specs) {
        bool matched = false;
        for (const DeviceInfo& d : all) {
            bool match = spec == "all" || (spec == "cpu" && d.type_name() == "cpu") ||
                         (spec == "gpu" && d.type_name() == "gpu") ||
                         spec == std::to_string(d.index);
            if (match) chosen.insert(d.index), matched = true;
        }
        if (matched) continue;
        if (spec == "cpu" || spec == "gpu")
            throw RuntimeError("--device " + spec + ": no " + spec + " device found");
        bool numeric = !spec.empty() && spec.find_first_not_of("0123456789") == std::string::npos;
        throw InputError("--device " + spec + ": " +
                         (numeric ? "no such device (" + std::to_string(all.size()) +
                                        " found; see `mcrt devices`)"
                                  : std::string("expected a device index, cpu, gpu or all")));
    }
    std::vector<DeviceInfo> result;
    for (int i : chosen) result.push_back(all[size_t(i)]);
    return result;
}

DeviceInfo select_device(long long index, const std::function<void(const std::string&)>& warn) {
    if (index < 0) throw InputError("--device " + std::to_string(index) + ": expected an index");
    return select_devices({std::to_string(index)}, warn).front();
}

}  // namespace mcrt
