// The estimator-file checker alone (host/render/user_source.h), without OpenCL: what it refuses,
// with which FILE:LINE, what it lets through (comments, inactive regions, the API include) and
// the text it hands the compiler.
#include <catch2/catch.hpp>
#include <string>

#include "common/error.h"
#include "render/user_source.h"

using namespace mcrt;

namespace {

const std::string kEstimate =
    "float3 estimate(const SceneView* scene, const SurfacePoint* sp, const SampleStream* stream,\n"
    "                uint* rays) {\n"
    "    return (float3)(0.5f);\n"
    "}\n";

UserSource check(const std::string& text) { return check_user_source("f.cl", text, "estimate"); }

// The message check() throws, "" when it accepts.
std::string refusal(const std::string& text) {
    try {
        check(text);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

bool starts_with(const std::string& s, const std::string& prefix) {
    return s.rfind(prefix, 0) == 0;
}

}  // namespace

TEST_CASE("an estimator file may include only \"api.cl\", in any spelling the preprocessor reads",
          "[user-source]") {
    for (const char* include :
         {"#include </etc/passwd>", "#include \"../../../etc/passwd\"", "#include \"rng.cl\"",
          "#  include <stdio.h>", "%:include </etc/passwd>", "#include_next </etc/passwd>",
          "#import </etc/passwd>", "/* a */ # /* b */ include </etc/passwd>",
          "#inc\\\nlude </etc/passwd>", "#include \\  \n</etc/passwd>", "#include \"api.cl\" x"}) {
        INFO(include);
        std::string message = refusal("/* line 1 */\n\n" + std::string(include) + "\n" + kEstimate);
        CHECK(starts_with(message, "f.cl:3: "));
        CHECK(message.find("may include only \"api.cl\"") != std::string::npos);
        CHECK(message.find('\n') == std::string::npos);
    }
    // Through a macro: `#include F` is refused whatever F is.
    std::string macro = refusal("#define F \"/etc/passwd\"\n#include F\n" + kEstimate);
    CHECK(starts_with(macro, "f.cl:2: #include F: "));
    // Inside a condition that may hold (a name the device or mcrt may define).
    CHECK(starts_with(refusal("#ifdef cl_khr_fp64\n#include </etc/passwd>\n#endif\n" + kEstimate),
                      "f.cl:2: "));
    CHECK(starts_with(
        refusal("#if __OPENCL_VERSION__ >= 120\n#else\n#include <x>\n#endif\n" + kEstimate),
        "f.cl:3: "));
    CHECK(starts_with(refusal("#if MY_FLAG\n#include <x>\n#endif\n" + kEstimate), "f.cl:2: "));
    CHECK(starts_with(refusal("#if __has_include(\"/etc/passwd\")\n#endif\n" + kEstimate),
                      "f.cl:1: "));
    CHECK(
        starts_with(refusal("#define S(x) #x\n#define I # include <x>\n" + kEstimate), "f.cl:2: "));
}

TEST_CASE(
    "includes in comments and in inactive regions are ignored, as a preprocessor ignores them",
    "[user-source]") {
    const std::string text =
        "// #include </etc/passwd>\n"
        "/* #include </etc/passwd>\n"
        "   #line 1 \"x\" */\n"
        "#if 0\n"
        "#include </etc/passwd>\n"
        "#line 5\n"
        "#elif defined(NOT_DEFINED_HERE) && 0\n"
        "#include </etc/passwd>\n"
        "#endif\n"
        "#define OFF 0\n"
        "#if OFF || (2 * 3 - 6)\n"
        "#include </etc/passwd>\n"
        "#endif\n"
        "#undef GONE\n"
        "#if GONE\n"
        "#include </etc/passwd>\n"
        "#endif\n"
        "#ifdef GONE\n"
        "#include </etc/passwd>\n"
        "#else\n"
        "#pragma OPENCL EXTENSION cl_khr_fp64 : enable\n"
        "#endif\n"
        "const char* s = \"#include </etc/passwd>\";\n"
        "#include \"api.cl\"\n" +
        kEstimate;
    UserSource out = check(text);
    CHECK(out.defines_function);
    // The API include is blanked in place: same length, same lines, the rest byte for byte.
    REQUIRE(out.text.size() == text.size());
    CHECK(out.text.find("#include \"api.cl\"") == std::string::npos);
    const size_t at = text.find("#include \"api.cl\"");
    CHECK(out.text.substr(at, 17) == std::string(17, ' '));
    CHECK(out.text.substr(0, at) == text.substr(0, at));
    CHECK(out.text.substr(at + 17) == text.substr(at + 17));
}

TEST_CASE("the checker refuses NUL bytes, #line, unbalanced conditionals and hostile pragmas",
          "[user-source]") {
    CHECK(refusal(kEstimate + std::string("/* x */\0\n", 9)) == "f.cl:5: contains a NUL byte");
    CHECK(starts_with(refusal("\n#line 1 \"render.cl\"\n" + kEstimate),
                      "f.cl:2: #line 1 \"render.cl\": "));
    CHECK(starts_with(refusal("# 7 \"x.cl\"\n" + kEstimate), "f.cl:1: "));
    CHECK(starts_with(refusal("#if 1\n" + kEstimate), "f.cl:1: #if without #endif"));
    CHECK(starts_with(refusal(kEstimate + "#endif\n"), "f.cl:5: #endif without #if"));
    CHECK(starts_with(refusal("#if 0\n#else\n#else\n#endif\n" + kEstimate),
                      "f.cl:3: #else after #else"));
    CHECK(starts_with(refusal("#pragma clang __debug crash\n" + kEstimate), "f.cl:1: "));
    CHECK(starts_with(refusal("_Pragma(\"clang __debug crash\")\n" + kEstimate), "f.cl:1: "));
    CHECK(starts_with(refusal("#pragma GCC dependency \"/etc/passwd\"\n" + kEstimate), "f.cl:1: "));
    CHECK(starts_with(refusal("#ident \"x\"\n" + kEstimate), "f.cl:1: "));
    CHECK(starts_with(refusal("// a comment ?\?/\n#include <x>\n" + kEstimate), "f.cl:1: "));
    CHECK(starts_with(refusal(kEstimate + "/* never closed\n"), "f.cl:5: unterminated /* comment"));
    // A comment whose line ends in backslash and spaces goes on (clang's splice), so the include
    // after it is inside a `//` comment and `/*` there opens nothing.
    CHECK(refusal("// \\  \n/*\n#include </etc/passwd>\n*/\n" + kEstimate) != "");
    CHECK(refusal("#pragma OPENCL EXTENSION cl_khr_fp64 : enable\n#error\n" + kEstimate) == "");
}

TEST_CASE("estimate must be defined at file scope, not only named in a comment or a string",
          "[user-source]") {
    CHECK_FALSE(
        check("/* float3 estimate(int x) { } */\nfloat f(void) { return 0; }\n").defines_function);
    CHECK_FALSE(check("const char* s = \"estimate(x) {\";\n").defines_function);
    CHECK_FALSE(check("float3 estimate(int x);\n").defines_function);
    CHECK_FALSE(check("#if 0\n" + kEstimate + "#endif\n").defines_function);
    CHECK(check("#ifdef SOME_OPTION\n" + kEstimate + "#endif\n").defines_function);
    CHECK(check(kEstimate).defines_function);
}

TEST_CASE("kernels and recursion in an estimator file are refused at their line", "[user-source]") {
    CHECK(refusal(kEstimate + "kernel void render(global float* x) { }\n") ==
          "f.cl:5: defines the kernel 'render': an estimator file defines functions, which mcrt's "
          "kernels call, not kernels (docs/ESTIMATORS.md)");
    CHECK(starts_with(refusal("__kernel void k(void) { }\n" + kEstimate),
                      "f.cl:1: defines the kernel 'k'"));
    CHECK(refusal("float g(int n) {\n    return n > 0 ? g(n - 1) : 0.0f;\n}\n" + kEstimate) ==
          "f.cl:2: 'g' calls itself: OpenCL C forbids recursion (OpenCL C 1.2 sec. 6.9)");
    CHECK(
        refusal("float h(int n);\nfloat g(int n) { return h(n); }\n"
                "float h(int n) { return n > 0 ? g(n - 1) : 0.0f; }\n" +
                kEstimate) ==
        "f.cl:2: 'g' calls itself (through h): OpenCL C forbids recursion (OpenCL C 1.2 sec. 6.9)");
    // Calls to other functions, and a name in a comment, are no cycle.
    CHECK(refusal("float h(int n) { return (float)n; /* h(n) */ }\n"
                  "float g(int n) { return h(n) + h(n + 1); }\n" +
                  kEstimate) == "");
}

TEST_CASE("private arrays beyond the limit are refused; the examples' sizes pass",
          "[user-source]") {
    const std::string big =
        "float3 estimate(const SceneView* scene, const SurfacePoint* sp,\n"
        "                const SampleStream* stream, uint* rays) {\n"
        "    float big[4194304];\n"
        "    return (float3)(big[*rays]);\n"
        "}\n";
    std::string message = refusal(big);
    CHECK(starts_with(message, "f.cl:3: private arrays of 16777216 bytes"));
    // Sizes through the file's macros, vector types, several declarators.
    CHECK(refusal(
              "#define N 2048\nfloat f(void) { float4 a[N][2], b[N]; return a[0][0].x + b[0]; }\n" +
              kEstimate) != "");
    UserSource small = check(
        "#define N 16\nfloat f(void) { float4 a[N], *p, b[2][3]; uint c[N * 2]; "
        "return 0; }\n" +
        kEstimate);
    CHECK(small.private_bytes == 16 * 16 + 2 * 3 * 16 + 32 * 4);
    CHECK(check("float f(int n) { float a[n > 0 ? 4 : 8]; return a[0]; }\n" + kEstimate)
              .private_bytes == 0);  // not a constant here: not counted
}
