// libFuzzer target: one config text through the strict parser and the config and scene loaders.
#include "framework/core/Error.h"
#include "tests/FuzzHarness.h"

#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    try {
        // Relative scene paths resolve against the working directory, like a config given as "c.json".
        shadowlab::fuzz::loadConfigText(std::string(reinterpret_cast<const char*>(data), size), "fuzz.json");
    } catch (const shadowlab::InputError&) {
        // Bad input, reported as such: the expected outcome for most inputs.
    }
    return 0;  // any other exception escapes and libFuzzer reports it as a crash
}
