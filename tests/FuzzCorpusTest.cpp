// A deterministic mutation corpus through the config and scene loaders, in-process and without GL:
// bit flips, truncations, GLB chunk-length lies, accessor/bufferView offsets and counts, deep
// nesting, huge numbers, duplicate keys and type swaps, generated from the shipped configs, the
// Debian test models and small generated files. Each case runs in a forked child so that a crash,
// an abort, a hang (alarm) or an allocation blow-up (peak RSS from wait4) is seen and attributed;
// each must end in success or in the bad-input error (InputError).
#include "framework/core/Error.h"
#include "framework/core/JsonParse.h"
#include "tests/FuzzHarness.h"
#include "tests/HostileInputs.h"
#include "tests/TestSupport.h"

#include <chrono>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

namespace shadowlab {
namespace {

namespace fs = std::filesystem;

#if defined(__SANITIZE_ADDRESS__)
constexpr long kMaxRssKiB = 2L << 20;  // ASan's shadow and quarantine add to every allocation
// A fork of an instrumented process costs many times a plain one (results/reference/ci_time_llvmpipe.md),
// so the sanitized tier runs every third case, a different third per loader; the plain tier
// (scripts/test.sh) runs them all.
constexpr size_t kCaseStride = 3;
#else
constexpr long kMaxRssKiB = 1L << 20;  // 1 GiB: the cap on any single case's peak resident memory
constexpr size_t kCaseStride = 1;
#endif
constexpr int kCaseSeconds = 30;  // a case still running after this is a hang

enum Outcome { kLoaded = 0, kInputError = 2, kOtherException = 3, kOutOfMemory = 4 };

/// One mutated input: the bytes and where to write them (beside the seed, so relative URIs resolve).
struct Case {
    std::string label;
    std::string path;
    std::string bytes;
};

std::string readFile(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

/// Placeholders let a JSON-level mutation leave text no JSON library would print.
const char* kDeep = "\"@@DEEP@@\"";
const char* kOverflow = "\"@@OVERFLOW@@\"";
std::string expandPlaceholders(std::string text) {
    auto replace = [&](const std::string& from, const std::string& to) {
        for (size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size())) text.replace(at, from.size(), to);
    };
    replace(kDeep, std::string(30000, '[') + std::string(30000, ']'));
    replace(kOverflow, "1e999");
    return text;
}

class Mutator {
public:
    explicit Mutator(uint64_t seed) : rng_(seed) {}

    size_t below(size_t n) { return n ? std::uniform_int_distribution<size_t>(0, n - 1)(rng_) : 0; }

    std::string bitFlips(std::string s) {
        for (size_t k = 0, n = 1 + below(8); k < n && !s.empty(); ++k) s[below(s.size())] ^= char(1u << below(8));
        return s;
    }
    std::string truncate(const std::string& s) { return s.substr(0, below(s.size())); }
    std::string spliceCopy(std::string s) {  // a slice of the file copied over another place
        if (s.size() < 8) return s;
        size_t from = below(s.size()), len = 1 + below(std::min<size_t>(64, s.size() - from)), to = below(s.size());
        return s.insert(to, s.substr(from, len));
    }
    /// GLB: the header's total length or a chunk length replaced by a lie.
    std::string glbLengthLie(std::string s) {
        if (s.size() < 20) return s;
        const uint32_t lies[] = {0, 1, 7, 0x7FFFFFFFu, 0xFFFFFFFFu, uint32_t(s.size() + 4), uint32_t(s.size() - 1)};
        uint32_t v = lies[below(std::size(lies))];
        size_t at = below(2) ? 8 : 12;  // header length, or the JSON chunk's length
        std::memcpy(&s[at], &v, 4);
        return s;
    }

    /// One structural change to a JSON document: a leaf or container replaced by a huge or odd
    /// value, a deep nest, an overflowing literal, another type, or removed; or a key duplicated.
    std::string jsonMutation(const Json& doc) {
        Json flat = doc.flatten();
        if (flat.empty() || !flat.is_object()) return doc.dump();
        auto it = flat.begin();
        std::advance(it, long(below(flat.size())));
        Json::json_pointer ptr(it.key());
        // Half the time aim at the container holding the leaf (objects and arrays get swapped too).
        if (below(2) && !ptr.empty()) ptr = ptr.parent_pointer();
        Json out = doc;
        const Json extremes[] = {1e38, 1e39, 3.5e38, -1e300, 1e300, 0, -1, 4294967296.0, 9007199254740993.0,
                                 2147483648.0, 1e-45, -0.0, 123456789012.0};
        switch (below(8)) {
        case 0:
        case 1: out[ptr] = extremes[below(std::size(extremes))]; break;
        case 2: out[ptr] = std::string("@@DEEP@@"); break;
        case 3: out[ptr] = std::string("@@OVERFLOW@@"); break;
        case 4: out[ptr] = Json::object(); break;
        case 5: out[ptr] = Json::array({1, "x", nullptr}); break;
        case 6: out[ptr] = "text"; break;
        default:
            if (!ptr.empty()) {
                Json& parent = out[ptr.parent_pointer()];
                if (parent.is_object()) parent.erase(ptr.back());
                else if (parent.is_array() && !parent.empty()) parent.erase(parent.size() - 1);
            }
        }
        std::string text = out.dump();
        // Placeholders were stored as strings: unquote them into raw text.
        text = expandPlaceholders(text);
        if (below(4) == 0 && text.size() > 2 && text[0] == '{') {
            // Duplicate the first key of the document: {"a": 1, ...} → {"a": 1, "a": 1, ...}.
            size_t colon = text.find(':'), comma = text.find(',');
            if (colon != std::string::npos && comma != std::string::npos && comma > colon)
                text.insert(comma, "," + text.substr(1, comma - 1));
        }
        return text;
    }

    /// glTF: an accessor's or bufferView's count, offset, length or stride set to an extreme.
    std::string gltfRangeLie(Json doc) {
        const char* arrays[] = {"accessors", "bufferViews", "buffers"};
        const char* keys[] = {"count", "byteOffset", "byteLength", "byteStride", "bufferView", "buffer"};
        Json& arr = doc[arrays[below(3)]];
        if (!arr.is_array() || arr.empty()) return doc.dump();
        const double values[] = {0, 1, 3, 4, 252, 1e6, 4294967295.0, 1e9, 1e15, 9007199254740992.0};
        arr[below(arr.size())][keys[below(std::size(keys))]] = values[below(std::size(values))];
        return doc.dump();
    }

private:
    std::mt19937_64 rng_;
};

/// The mutations of one seed file (JSON text or GLB bytes).
std::vector<Case> mutationsOf(const std::string& seedPath, const std::string& bytes, const std::string& outPath,
                              bool isScene, int count, uint64_t seed) {
    std::vector<Case> cases;
    Mutator m(seed);
    bool glb = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
    Json doc;
    bool parsed = false;
    if (!glb) {
        try {
            doc = Json::parse(bytes);
            parsed = true;
        } catch (const std::exception&) {}
    }
    for (int k = 0; k < count; ++k) {
        std::string out;
        size_t op = m.below(glb ? 4 : parsed ? (isScene ? 7 : 6) : 3);
        switch (op) {
        case 0: out = m.bitFlips(bytes); break;
        case 1: out = m.truncate(bytes); break;
        case 2: out = m.spliceCopy(bytes); break;
        case 3:
            if (glb) { out = m.glbLengthLie(bytes); break; }
            [[fallthrough]];
        case 4:
        case 5: out = m.jsonMutation(doc); break;
        default: out = m.gltfRangeLie(doc); break;
        }
        cases.push_back({seedPath + " #" + std::to_string(k), outPath, std::move(out)});
    }
    return cases;
}

/// Runs in the child: loads the case, returns the outcome as the exit code.
int loadInChild(const Case& c, bool isScene) {
    try {
        size_t triangles = isScene ? fuzz::loadSceneFile(c.path) : fuzz::loadConfigText(readFile(c.path), c.path);
        return triangles > 0 ? kLoaded : kOtherException;
    } catch (const InputError&) {
        return kInputError;
    } catch (const std::bad_alloc&) {
        return kOutOfMemory;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "unexpected exception: %s\n", e.what());
        return kOtherException;
    }
}

struct Tally {
    size_t loaded = 0, rejected = 0;
    long maxRssKiB = 0;
    double maxSeconds = 0;
    std::string worstRss;
};

void runCase(const Case& c, bool isScene, Tally& t) {
    { std::ofstream(c.path, std::ios::binary) << c.bytes; }
    auto start = std::chrono::steady_clock::now();
    pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
        alarm(kCaseSeconds);
        std::_Exit(loadInChild(c, isScene));
    }
    int status = 0;
    struct rusage usage {};
    ASSERT_EQ(wait4(pid, &status, 0, &usage), pid);
    double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    t.maxSeconds = std::max(t.maxSeconds, seconds);
    if (usage.ru_maxrss > t.maxRssKiB) t.maxRssKiB = usage.ru_maxrss, t.worstRss = c.label;
    ASSERT_FALSE(WIFSIGNALED(status)) << c.label << ": killed by signal " << WTERMSIG(status)
                                      << (WTERMSIG(status) == SIGALRM ? " (hang: over the time bound)" : "")
                                      << "; the input is kept at " << c.path + ".failed";
    int code = WEXITSTATUS(status);
    EXPECT_TRUE(code == kLoaded || code == kInputError) << c.label << ": exit " << code;
    EXPECT_LE(usage.ru_maxrss, kMaxRssKiB) << c.label << ": peak " << usage.ru_maxrss / 1024 << " MiB";
    (code == kLoaded ? t.loaded : t.rejected)++;
}

void report(const char* what, size_t cases, const Tally& t) {
    std::printf("%s: %zu cases, %zu loaded, %zu rejected as bad input, 0 signals; peak RSS %ld MiB (%s), slowest %.2f s\n",
                what, cases, t.loaded, t.rejected, t.maxRssKiB / 1024, t.worstRss.c_str(), t.maxSeconds);
}

/// Runs every case; the first that crashes or hangs stops the run, its input kept as PATH.failed.
void runCorpus(const char* what, const std::vector<Case>& cases, bool isScene) {
    Tally t;
    size_t ran = 0;
    for (size_t i = isScene ? 0 : kCaseStride / 2; i < cases.size(); i += kCaseStride, ++ran) {
        const Case& c = cases[i];
        runCase(c, isScene, t);
        if (::testing::Test::HasFatalFailure()) {
            fs::copy_file(c.path, c.path + ".failed", fs::copy_options::overwrite_existing);
            return;
        }
    }
    report(what, ran, t);
    EXPECT_GT(t.loaded, 0u);  // the corpus reaches past the checks too, not only into them
}

TEST(FuzzCorpusTest, SceneLoaderSurvivesMutatedGltfAndGlb) {
    std::string dir = test::makeTempDir("fuzz-scenes");
    std::vector<Case> cases;
    uint64_t seed = 1;
    auto addSeed = [&](const std::string& seedPath, const std::string& bytes, const std::string& ext, int count) {
        // Mutations are written into a copy of the seed's folder, so that its .bin and images resolve.
        std::string copy = dir + "/seed" + std::to_string(seed);
        fs::create_directories(copy);
        if (!seedPath.empty())
            for (const auto& e : fs::directory_iterator(fs::path(seedPath).parent_path()))
                if (e.is_regular_file() && e.file_size() < (4u << 20)) fs::copy_file(e.path(), copy / e.path().filename());
        auto more = mutationsOf(seedPath.empty() ? "generated" + ext : seedPath, bytes, copy + "/mutated" + ext, true, count, seed++);
        cases.insert(cases.end(), more.begin(), more.end());
    };
    std::vector<fs::path> models;
    for (const auto& e : fs::recursive_directory_iterator(test::kAssimpGltf))
        if (e.path().extension() == ".gltf" || e.path().extension() == ".glb") models.push_back(e.path());
    std::sort(models.begin(), models.end());  // directory order is not deterministic; the seeds must be
    for (const fs::path& m : models)  // the 1.8 MB engine, the one big real model, gets twice the mutations
        addSeed(m.string(), readFile(m.string()), m.extension().string(), fs::file_size(m) > (1u << 20) ? 24 : 12);
    addSeed("", test::triangleGltf(), ".gltf", 60);
    addSeed("", test::glbOf(test::triangleGltf()), ".glb", 60);
    ASSERT_GE(cases.size(), 600u);
    runCorpus("scene loader", cases, true);
}

TEST(FuzzCorpusTest, ConfigLoaderSurvivesMutatedConfigs) {
    std::string dir = test::makeTempDir("fuzz-configs");
    std::vector<Case> cases;
    uint64_t seed = 1000;
    auto addSeed = [&](const std::string& seedPath, const std::string& bytes, int count) {
        // The shipped configs name their scene files by absolute path, so they load from here too.
        auto more = mutationsOf(seedPath.empty() ? "generated config" : seedPath, bytes, dir + "/mutated.json", false, count, seed++);
        cases.insert(cases.end(), more.begin(), more.end());
    };
    std::vector<std::string> seeds;
    for (const auto& e : fs::recursive_directory_iterator(std::string(SHADOWLAB_SOURCE_DIR) + "/configs"))
        if (e.path().extension() == ".json" && e.path().string().find(".sweep.") == std::string::npos)
            seeds.push_back(e.path().string());  // sweep files are not configs: their runs are
    for (const auto& e : fs::directory_iterator(SHADOWLAB_TEST_DATA))
        if (e.path().extension() == ".json") seeds.push_back(e.path().string());
    std::sort(seeds.begin(), seeds.end());  // directory order is not deterministic
    for (const auto& s : seeds) addSeed(s, readFile(s), 15);
    addSeed("", test::configWith({}), 200);
    ASSERT_GE(cases.size(), 500u);
    runCorpus("config loader", cases, false);
}

} // namespace
} // namespace shadowlab
