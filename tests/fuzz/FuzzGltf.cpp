// libFuzzer target: one .gltf/.glb file through the glTF loader. The loader reads files (buffers
// may be relative URIs), so each input is written to a per-process temporary file first.
#include "framework/core/Error.h"
#include "tests/FuzzHarness.h"

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <unistd.h>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static const std::string path = "/tmp/shadowlab-fuzz-" + std::to_string(::getpid()) + ".glb";
    FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) return 0;
    std::fwrite(data, 1, size, f);
    std::fclose(f);
    try {
        shadowlab::fuzz::loadSceneFile(path);
    } catch (const shadowlab::InputError&) {
    }
    return 0;
}
