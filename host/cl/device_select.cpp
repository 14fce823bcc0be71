#include "cl/device_select.h"

#include <algorithm>
#include <cctype>
#include <set>

#include "cl/no_device.h"
#include "common/activity.h"
#include "common/error.h"

namespace mcrt {

namespace {

std::string lower(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return s;
}

// A platform spec ("intel", "pocl", "nvidia", ...) matches a device whose platform name or vendor
// contains it, ignoring case: PoCL's platform is "Portable Computing Language" by "The pocl
// project", Intel's "Intel(R) OpenCL" by "Intel(R) Corporation".
bool platform_matches(const std::string& spec, const DeviceInfo& d) {
    const std::string s = lower(spec);
    return lower(d.platform_name).find(s) != std::string::npos ||
           lower(d.platform_vendor).find(s) != std::string::npos;
}

bool is_reserved(const std::string& spec) {
    return spec == "all" || spec == "cpu" || spec == "gpu";
}

}  // namespace

static bool numeric(const std::string& spec) {
    return !spec.empty() && spec.find_first_not_of("0123456789") == std::string::npos;
}

std::vector<DeviceInfo> select_devices(const std::vector<std::string>& specs,
                                       const std::function<void(const std::string&)>& warn) {
    const Activity activity("setting up the OpenCL devices");
    std::vector<DeviceInfo> all = enumerate_devices(warn);
    if (all.empty()) throw RuntimeError(no_device_message());
    if (specs.empty()) return {all.front()};
    std::set<int> chosen;
    for (const std::string& spec : specs) {
        bool matched = false;
        for (const DeviceInfo& d : all) {
            bool match = spec == "all" || (spec == "cpu" && d.type_name() == "cpu") ||
                         (spec == "gpu" && d.type_name() == "gpu") ||
                         spec == std::to_string(d.index) ||
                         (!is_reserved(spec) && !numeric(spec) && !spec.empty() &&
                          platform_matches(spec, d));
            if (match) chosen.insert(d.index), matched = true;
        }
        if (matched) continue;
        if (spec == "cpu" || spec == "gpu")
            throw RuntimeError("--device " + spec + ": no " + spec + " device found");
        if (numeric(spec))
            throw InputError("--device " + spec + ": no such device (" +
                             std::to_string(all.size()) + " found; see `mcrt devices`)");
        if (spec.empty() || spec.find_first_of(" \t") != std::string::npos)
            throw InputError("--device '" + spec +
                             "': expected a device index, cpu, gpu, all or a platform name");
        throw InputError("--device " + spec +
                         ": expected a device index, cpu, gpu, all or a platform name; no "
                         "platform's name or vendor contains '" +
                         spec + "' (see `mcrt devices`)");
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
