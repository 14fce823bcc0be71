// The extension `mcrt._mcrt` (pybind11): contexts on a render session (render/session.h), scenes
// loaded once, renders whose images numpy views without a copy. The keyword interface, its type
// checks and the one-shot mcrt.render() are python/mcrt/__init__.py's; a render's options arrive
// here as the command line's arguments and are parsed and checked by the command line's own
// parser (cli/render_command.h), so that defaults, validation and messages are the command's.
// Renders and loads run on threads of their own (interruptible.h), so that Ctrl-C reaches them.
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "cl/device.h"
#include "cl/device_select.h"
#include "cli/render_command.h"
#include "cli/stats_json.h"
#include "cli/usage_errors.h"
#include "cli/validators.h"
#include "common/error.h"
#include "common/test_hooks.h"
#include "image/image.h"
#include "interruptible.h"
#include "render/estimator_file.h"
#include "render/memory_estimate.h"
#include "render/session.h"
#include "render/variants.h"

namespace py = pybind11;

namespace mcrt {
namespace {

// The module's exception classes (created in PYBIND11_MODULE), raised by the translator below
// from these C++ types.
PyObject* g_setting_error = nullptr;
PyObject* g_scene_error = nullptr;
PyObject* g_estimator_error = nullptr;
PyObject* g_device_error = nullptr;

struct PySettingError : std::runtime_error {
    using std::runtime_error::runtime_error;
};
struct PySceneError : std::runtime_error {
    using std::runtime_error::runtime_error;
};
struct PyDeviceError : std::runtime_error {
    using std::runtime_error::runtime_error;
};
// A user's estimator refused: the first line is the message; the rest the build log, if any.
struct PyEstimatorError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// The line number of "NAME:LINE: ..." in an estimator error's first line; -1 when it has none.
long estimator_line(const std::string& message, const std::string& name) {
    if (name.empty() || message.compare(0, name.size() + 1, name + ":") != 0) return -1;
    size_t at = name.size() + 1, end = at;
    while (end < message.size() && std::isdigit(static_cast<unsigned char>(message[end]))) ++end;
    return end > at ? std::stol(message.substr(at, end - at)) : -1;
}

void raise_estimator_error(const std::string& what, const std::string& name) {
    const size_t newline = what.find('\n');
    const std::string first = what.substr(0, newline);
    py::object error = py::reinterpret_borrow<py::object>(g_estimator_error)(first);
    const long line = estimator_line(first, name);
    error.attr("line") = line >= 0 ? py::object(py::int_(line)) : py::object(py::none());
    error.attr("log") = newline == std::string::npos ? std::string() : what.substr(newline + 1);
    PyErr_SetObject(g_estimator_error, error.ptr());
}

// An estimator's name travels in the exception text: "NAME\x1fMESSAGE".
constexpr char kNameSeparator = '\x1f';

void translate(std::exception_ptr p) {
    try {
        if (p) std::rethrow_exception(p);
    } catch (const PySettingError& e) {
        PyErr_SetString(g_setting_error, e.what());
    } catch (const PySceneError& e) {
        PyErr_SetString(g_scene_error, e.what());
    } catch (const PyDeviceError& e) {
        PyErr_SetString(g_device_error, e.what());
    } catch (const PyEstimatorError& e) {
        const std::string what = e.what();
        const size_t cut = what.find(kNameSeparator);
        raise_estimator_error(what.substr(cut + 1), what.substr(0, cut));
    }
}

// A user's estimator: its name (what messages and build errors call it) and checked text.
struct Estimator {
    std::string name, text;
};

// What an InputError means where it is thrown: a setting, the scene, or a user's estimator.
enum class InputKind { Setting, Scene, Estimator };

// Runs `f`, turning the library's errors into the module's: a SettingError of the estimator
// file and an InputError that names the estimator `estimator` become EstimatorError, other input
// errors those of `kind`, runtime failures DeviceError; the text is the command line's line.
template <typename F>
auto translating(F&& f, InputKind kind, const std::string& estimator = "") -> decltype(f()) {
    auto input_error = [&](const std::string& what, bool of_estimator) {
        if (of_estimator || kind == InputKind::Estimator)
            throw PyEstimatorError(estimator + kNameSeparator + what);
        if (kind == InputKind::Scene) throw PySceneError(what);
        throw PySettingError(what);
    };
    try {
        return f();
    } catch (const SettingError& e) {
        const std::string what = flag_error(e).what();
        const bool of_estimator = e.setting == "estimator_file";
        // The estimator's own text, as a file's would be told without its flag.
        input_error(of_estimator && kind == InputKind::Estimator ? e.detail : what, of_estimator);
        throw;  // not reached: input_error throws
    } catch (const InputError& e) {
        const std::string what = e.what();
        input_error(what, !estimator.empty() &&
                              what.compare(0, estimator.size() + 1, estimator + ":") == 0);
        throw;  // not reached: input_error throws
    } catch (const RuntimeError& e) {
        throw PyDeviceError(e.what());
    }
}

// What a context holds: the session, until close().
struct ContextState {
    std::unique_ptr<RenderSession> session;
    std::vector<std::string> warnings;  // of the device selection
    std::mutex mutex;                   // guards `session` against close() during a render
    // Set by close(): read without the mutex, which a render ending in the background may hold.
    std::atomic<bool> closed{false};
};

struct ResultData {
    RenderResult result;
    RenderOptions options;
    std::string stats_json;
    std::vector<std::string> warnings;
};

struct PyResult {
    std::shared_ptr<ResultData> data;
};

struct PyScene {
    std::shared_ptr<ContextState> context;
    std::shared_ptr<SessionScene> scene;
    std::vector<std::string> load_warnings;
};

// `mutex` locked, waited for without the GIL (a render ending in the background may hold it).
std::unique_lock<std::mutex> lock_without_gil(std::mutex& mutex) {
    py::gil_scoped_release release;
    return std::unique_lock<std::mutex>(mutex);
}

// The options of `args` (the command line's `render` arguments after the scene) as the command
// line parses and checks them; SettingError with the command line's message otherwise.
RenderOptions parse_render_options(const std::string& scene, const std::string& materials,
                                   const std::vector<std::string>& args) {
    CLI::App app{"mcrt"};
    RenderOptions o;
    add_render_command(app, o);
    refuse_empty_values(app);
    // The output is the caller's (Result.save): a placeholder satisfies the required option.
    std::vector<std::string> words = {
        "mcrt", "render", scene, "--out", "mcrt-python.exr", "--materials", materials, "--quiet"};
    words.insert(words.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& w : words) argv.push_back(w.data());
    try {
        app.parse(int(argv.size()), argv.data());
    } catch (const CLI::ParseError& e) {
        throw PySettingError(usage_error_message(app, e, int(argv.size()), argv.data()));
    }
    if (o.width * int64_t(o.height) * o.spp >= (int64_t(1) << 40))
        throw PySettingError("--width × --height × --spp is too large");
    return o;
}

py::object json_to_python(const std::string& text) {
    return py::module_::import("json").attr("loads")(text);
}

PyResult render_scene(PyScene& self, const std::vector<std::string>& args,
                      const Estimator* estimator, const py::object& progress) {
    const auto start = std::chrono::steady_clock::now();
    std::shared_ptr<ContextState> context = self.context;
    auto data = std::make_shared<ResultData>();
    RenderOptions& o = data->options;
    o = parse_render_options(self.scene->path, self.scene->materials, args);
    RenderRequest request = translating([&] { return render_request(o); }, InputKind::Setting);
    if (estimator) {
        if (!o.estimator_file.empty())
            throw PySettingError("estimator and estimator_file name two estimators; give one");
        o.estimator_file = estimator->name;
        request.settings.estimator_file = estimator->name;
        request.settings.estimator_source = estimator->text;
    }
    const std::string user_estimator = o.estimator_file;
    std::shared_ptr<SessionScene> scene = self.scene;

    // The render runs on a thread of its own without the GIL (run_interruptible): progress and
    // Ctrl-C are seen from this thread. The work holds what it uses, as it may outlive this call.
    run_interruptible(
        [context, scene, data, request, user_estimator, start](Job& job) {
            const RenderOptions& o = data->options;
            RenderControl control;
            control.time_limit = o.time_limit;
            control.interrupted = &job.interrupted;
            control.keep_replicate_means = true;
            ProgressSink sink = [&job](uint32_t done, uint32_t total,
                                       const std::vector<DeviceReport>&) {
                job.report(done, total);
            };
            WarningSink warn = [data](const std::string& w) { data->warnings.push_back(w); };
            translating(
                [&] {
                    std::lock_guard<std::mutex> context_lock(context->mutex);
                    if (!context->session)
                        throw PyDeviceError("the context of this scene is closed");
                    std::lock_guard<std::mutex> scene_lock(scene->use);
                    const RenderPlan plan = plan_session_render(*scene, request, warn, {},
                                                                &context->session->environments());
                    check_host_memory(
                        "a " + std::to_string(o.width) + "x" + std::to_string(o.height) + " render",
                        render_host_bytes(o.width, o.height, plan.settings.replicates));
                    const double seconds_to_render =
                        std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
                            .count();
                    data->result = context->session->render(scene, plan, sink, control, warn);
                    if (job.interrupted) return 0;  // the caller raised already
                    if (!data->result.stopped_by.empty())
                        warn("stopped by " + data->result.stopped_by + " after " +
                             std::to_string(data->result.spp) + " of " + std::to_string(o.spp) +
                             " samples per pixel");
                    check_render_result(data->result, warn);
                    const double total =
                        std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
                            .count();
                    data->stats_json = render_stats_json({o, plan, scene->prepared, data->result,
                                                          total, seconds_to_render})
                                           .dump();
                    return 0;
                },
                InputKind::Setting, user_estimator);
        },
        progress);
    return PyResult{data};
}

py::array_t<float> image_view(const py::object& owner, const Image& image,
                              const std::vector<float>& values) {
    const py::ssize_t h = image.height, w = image.width;
    // A view on the result's own floats; `owner` (the Result) is kept alive by the array.
    return py::array_t<float>({h, w, py::ssize_t(3)},
                              {py::ssize_t(sizeof(float)) * 3 * w, py::ssize_t(sizeof(float)) * 3,
                               py::ssize_t(sizeof(float))},
                              values.data(), owner);
}

// The replicates' mean images as (K, H, W, 3), a view on the result's floats, which hold them
// pixel-major (Accumulator::replicate_means); None with one replicate.
py::object replicate_view(const py::object& owner, const RenderResult& result) {
    if (result.replicate_means.empty()) return py::none();
    const py::ssize_t k = result.replicates, h = result.image.height, w = result.image.width;
    const py::ssize_t f = sizeof(float);
    return py::array_t<float>({k, h, w, py::ssize_t(3)}, {3 * f, 3 * k * w * f, 3 * k * f, f},
                              result.replicate_means.data(), owner);
}

py::dict device_dict(const DeviceInfo& d) {
    py::dict r;
    r["index"] = d.index;
    r["name"] = d.name;
    r["type"] = d.type_name();
    r["platform"] = d.platform_name;
    r["platform_vendor"] = d.platform_vendor;
    r["version"] = d.version;
    r["driver_version"] = d.driver_version;
    r["compute_units"] = d.compute_units;
    r["global_memory"] = d.global_memory;
    r["max_allocation"] = d.max_allocation;
    return r;
}

}  // namespace
}  // namespace mcrt

PYBIND11_MODULE(_mcrt, m) {
    using namespace mcrt;
    m.doc() = "mcrt's render session (the Python API is the package mcrt)";

    g_setting_error = PyErr_NewExceptionWithDoc("mcrt.SettingError",
                                                "A render setting the command line would refuse.",
                                                PyExc_ValueError, nullptr);
    g_scene_error = PyErr_NewExceptionWithDoc("mcrt.SceneError", "A scene that cannot be read.",
                                              PyExc_ValueError, nullptr);
    g_estimator_error = PyErr_NewExceptionWithDoc(
        "mcrt.EstimatorError",
        "A user's estimator that is refused or does not build; `line` is its line (or None), "
        "`log` the build log.",
        PyExc_ValueError, nullptr);
    g_device_error = PyErr_NewExceptionWithDoc("mcrt.DeviceError",
                                               "No device, or a device failure during a render.",
                                               PyExc_RuntimeError, nullptr);
    m.add_object("SettingError", py::handle(g_setting_error));
    m.add_object("SceneError", py::handle(g_scene_error));
    m.add_object("EstimatorError", py::handle(g_estimator_error));
    m.add_object("DeviceError", py::handle(g_device_error));
    py::register_exception_translator(&translate);

    m.def("devices", [] {
        // OpenCL's start-up (loading every platform's driver) runs on a thread of its own, as a
        // render does (run_interruptible): Ctrl-C raises at once, other Python threads run.
        auto devices = std::make_shared<std::vector<DeviceInfo>>();
        run_interruptible(
            [devices](Job&) {
                test_pause("start-up");
                *devices = enumerate_devices([](const std::string&) {});
            },
            py::none());
        py::list list;
        for (const DeviceInfo& d : *devices) list.append(device_dict(d));
        return list;
    });
    m.def(
        "_wait_background", [] { join_background(true); },
        "Waits for work that an interrupted render or load left running (called at exit).");
    m.def("_background_running", &background_running,
          "How many interrupted renders and loads are still running (tests).");
    m.def("variants_json", [] { return variants_json(); });

    py::class_<Estimator>(m, "Estimator")
        .def_property_readonly("name", [](const Estimator& e) { return e.name; })
        .def("__repr__", [](const Estimator& e) { return "<mcrt.Estimator " + e.name + ">"; });

    py::class_<PyResult>(m, "Result")
        .def_property_readonly("image",
                               [](py::object self) {
                                   const PyResult& r = self.cast<const PyResult&>();
                                   const Image& image = r.data->result.image;
                                   return image_view(self, image, image.rgb);
                               })
        .def_property_readonly("variance",
                               [](py::object self) {
                                   const PyResult& r = self.cast<const PyResult&>();
                                   const Image& image = r.data->result.image;
                                   return image_view(self, image, image.variance);
                               })
        .def_property_readonly("replicate_images",
                               [](py::object self) {
                                   const PyResult& r = self.cast<const PyResult&>();
                                   return replicate_view(self, r.data->result);
                               })
        .def_property_readonly("spp", [](const PyResult& r) { return r.data->result.spp; })
        .def_property_readonly("replicates",
                               [](const PyResult& r) { return r.data->result.replicates; })
        .def_property_readonly("stopped_by",
                               [](const PyResult& r) { return r.data->result.stopped_by; })
        .def_property_readonly("warnings", [](const PyResult& r) { return r.data->warnings; })
        .def_property_readonly("stats",
                               [](const PyResult& r) { return json_to_python(r.data->stats_json); })
        .def(
            "save",
            [](const PyResult& r, const std::string& path, const std::string& png,
               double exposure) {
                const ResultData& d = *r.data;
                translating(
                    [&] {
                        if (!std::isfinite(exposure) || exposure < -64 || exposure > 64)
                            throw InputError("--exposure " + std::to_string(exposure) +
                                             ": expected a number in [-64, 64]");
                        py::gil_scoped_release release;
                        write_exr(path, d.result.image, exr_attributes(d.options, d.result));
                        if (!png.empty())
                            write_png(path == png ? path + ".png" : png, d.result.image,
                                      float(exposure));
                        return 0;
                    },
                    InputKind::Setting);
            },
            py::arg("path"), py::arg("png") = "", py::arg("exposure") = 0.0);

    py::class_<PyScene>(m, "Scene")
        .def_property_readonly("path", [](const PyScene& s) { return s.scene->path; })
        .def_property_readonly("materials", [](const PyScene& s) { return s.scene->materials; })
        .def_property_readonly(
            "info",
            [](const PyScene& s) {
                const PreparedScene& p = s.scene->prepared;
                py::dict info;
                info["path"] = s.scene->path;
                info["materials"] = s.scene->materials;
                info["triangles"] = p.scene.triangle_count();
                info["emitters"] = p.gpu.lights.size();
                info["textures"] = p.scene.images.size();
                info["cameras"] = p.scene.gltf_camera_types.size();
                const glm::vec3 lo = p.scene.bounds_min(), hi = p.scene.bounds_max();
                info["bounds"] = py::make_tuple(py::make_tuple(lo.x, lo.y, lo.z),
                                                py::make_tuple(hi.x, hi.y, hi.z));
                info["seconds_load"] = p.seconds_load;
                info["warnings"] = s.load_warnings;
                return info;
            })
        .def(
            "_render",
            [](PyScene& s, const std::vector<std::string>& args, const Estimator* estimator,
               const py::object& progress) { return render_scene(s, args, estimator, progress); },
            py::arg("args"), py::arg("estimator") = nullptr, py::arg("progress") = py::none());

    py::class_<ContextState, std::shared_ptr<ContextState>>(m, "_Context")
        .def(py::init([](const std::vector<std::string>& devices) {
                 auto state = std::make_shared<ContextState>();
                 // The devices' start-up (drivers, contexts, queues) on a thread of its own, as
                 // devices() does; abandoned at Ctrl-C, it ends in the background.
                 run_interruptible(
                     [state, devices](Job&) {
                         translating(
                             [&] {
                                 WarningSink warn = [&](const std::string& w) {
                                     state->warnings.push_back(w);
                                 };
                                 test_pause("start-up");
                                 state->session = std::make_unique<RenderSession>(
                                     select_devices(devices, warn), warn);
                                 return 0;
                             },
                             InputKind::Setting);
                     },
                     py::none());
                 return state;
             }),
             py::arg("devices"))
        .def_property_readonly("warnings", [](const ContextState& c) { return c.warnings; })
        .def_property_readonly("closed", [](ContextState& c) { return c.closed.load(); })
        .def_property_readonly("_environment_reads",
                               [](ContextState& c) {
                                   std::unique_lock<std::mutex> lock = lock_without_gil(c.mutex);
                                   return c.session ? c.session->environments().reads() : 0;
                               })
        .def_property_readonly("_environment_uploads",
                               [](ContextState& c) {
                                   std::unique_lock<std::mutex> lock = lock_without_gil(c.mutex);
                                   return c.session ? c.session->environment_uploads() : 0;
                               })
        .def_property_readonly("devices",
                               [](ContextState& c) {
                                   std::unique_lock<std::mutex> lock = lock_without_gil(c.mutex);
                                   py::list list;
                                   if (c.session)
                                       for (const DeviceContext* d : c.session->devices())
                                           list.append(device_dict(d->info));
                                   return list;
                               })
        .def("close",
             [](ContextState& c) {
                 py::gil_scoped_release release;  // waits for a render in another thread
                 c.closed = true;
                 std::lock_guard<std::mutex> lock(c.mutex);
                 c.session.reset();
             })
        .def(
            "load",
            [](std::shared_ptr<ContextState> c, const std::string& path,
               const std::string& materials) {
                // The materials name is checked as the command line checks --materials.
                parse_render_options("scene.gltf", materials, {});
                // Read on a thread of its own, as a render runs (run_interruptible): Ctrl-C
                // raises at once and the load, abandoned, ends in the background.
                struct Loaded {
                    std::shared_ptr<SessionScene> scene;
                    std::vector<std::string> warnings;
                };
                auto loaded = std::make_shared<Loaded>();
                run_interruptible(
                    [c, loaded, path, materials](Job&) {
                        if (c->closed) throw PyDeviceError("the context is closed");
                        WarningSink warn = [loaded](const std::string& w) {
                            loaded->warnings.push_back(w);
                        };
                        loaded->scene = translating(
                            [&] {
                                return load_session_scene(path, materials, LightSelection::Power,
                                                          SceneSource{}, warn);
                            },
                            InputKind::Scene);
                    },
                    py::none());
                PyScene scene;
                scene.context = c;
                scene.scene = loaded->scene;
                scene.load_warnings = loaded->warnings;
                return scene;
            },
            py::arg("path"), py::arg("materials") = "gltf")
        .def(
            "estimator",
            [](const ContextState&, const std::string& source, const std::string& name) {
                Estimator e;
                e.name = name;
                e.text = translating([&] { return check_estimator_source(name, source); },
                                     InputKind::Estimator, name);
                return e;
            },
            py::arg("source"), py::arg("name") = "estimator.cl");
}
