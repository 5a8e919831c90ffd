// shadowlab-gui driven without a person: launched under Xvfb (GLX on llvmpipe) with its automation
// options, which act through the same functions as the widgets (selectAlgorithm, applyParamChange,
// the path recorder, the config writer). CPU tier: it needs no GL context of its own.
#include "framework/core/Text.h"
#include "framework/experiment/Config.h"
#include "tests/HostileInputs.h"
#include "tests/TestSupport.h"

#include <stb_image.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

namespace shadowlab {
namespace {

namespace fs = std::filesystem;

#ifdef SHADOWLAB_GUI_BINARY
const std::string kGui = SHADOWLAB_GUI_BINARY;
#else
const std::string kGui;
#endif

const std::string kSmoke = std::string(SHADOWLAB_SOURCE_DIR) + "/configs/smoke.json";
constexpr int kPanelWidth = 380; ///< GuiState::panelWidth: the panel is x < 380 at the default 1280×800

/// Skips the test (with why) where the GUI cannot be launched; returns the command prefix otherwise.
std::string guiCommand() {
    if (kGui.empty()) return "";
    std::string out;
    if (test::runCommand("command -v xvfb-run", out) != 0) return "";
    // A private X server per run (-a picks a free display); Mesa's software GLX renders on the CPU.
    return "LIBGL_ALWAYS_SOFTWARE=1 xvfb-run -a -s \"-screen 0 1280x800x24\" " + kGui;
}

/// Runs the GUI under Xvfb. ctest -j may start two `xvfb-run -a` at once, and both can pick the same
/// free display number; the loser reports that Xvfb failed to start, so try again.
int runGui(const std::string& command, std::string& out) {
    int rc = 0;
    for (int attempt = 0; attempt < 3; ++attempt) {
        rc = test::runCommand(command, out);
        if (out.find("Xvfb failed to start") == std::string::npos) break;
    }
    return rc;
}

// scripts/setup.sh installs GLFW, ImGui and Xvfb, so a missing piece is a failure, not a skip.
#define REQUIRE_GUI(cmd)                                                                                 \
    std::string cmd = guiCommand();                                                                      \
    if (kGui.empty()) FAIL() << "shadowlab-gui was not built (needs libglfw3-dev and libimgui-dev)";   \
    if (cmd.empty()) FAIL() << "xvfb-run is missing (Debian package xvfb)";

Json readJson(const std::string& path) {
    std::ifstream in(path);
    std::stringstream ss;
    ss << in.rdbuf();
    return Json::parse(ss.str());
}

glm::vec3 vec3(const Json& j) { return {j[0].get<float>(), j[1].get<float>(), j[2].get<float>()}; }

struct Rgb {
    int r, g, b;
    int max() const { return std::max({r, g, b}); }
};

class Png {
public:
    explicit Png(const std::string& path) { data_ = stbi_load(path.c_str(), &w_, &h_, &n_, 3); }
    ~Png() { if (data_) stbi_image_free(data_); }
    bool ok() const { return data_ != nullptr; }
    int width() const { return w_; }
    int height() const { return h_; }
    Rgb at(int x, int y) const {
        const unsigned char* p = data_ + (size_t(y) * size_t(w_) + size_t(x)) * 3;
        return {p[0], p[1], p[2]};
    }

private:
    unsigned char* data_ = nullptr;
    int w_ = 0, h_ = 0, n_ = 0;
};

// Thresholds of the screenshot checks, measured on llvmpipe (Mesa 22.3) at 1280×800 after 6 frames
// of smoke.json with psv (path frame 1): the panel is ~55 % dark window background and ~35 % blue
// headers, frames and slider grabs, with ~1,400 distinct colours from anti-aliased text; the ground
// is ~200 grey where lit and ~94 where shadowed (ambient 0.15), ~55 % and ~2.7 % of the scene region.
constexpr size_t kMinPanelColours = 50;     ///< text anti-aliasing alone gives hundreds
constexpr double kMinPanelBlue = 0.10;      ///< ImGui's dark style: headers, frames and slider grabs
constexpr double kMinPanelDark = 0.20;      ///< ImGui's dark window background
constexpr double kMinLitGround = 0.20;      ///< bright neutral grey pixels of the scene region
constexpr double kMinShadowedGround = 0.01; ///< dark neutral grey: the sphere's and torus' shadows (~7,000 px)

TEST(GuiTest, SwitchesAlgorithmSetsParameterPlaysAndShowsShadows) {
    REQUIRE_GUI(gui);
    std::string dir = test::makeTempDir("gui");
    std::string shot = dir + "/gui.png", report = dir + "/report.json";
    // The app opens on the config's first entry (shadow_map); switch to the registered psv, change
    // a Rebuild and an Update parameter through applyParamChange (the widgets' path), and play 6
    // frames of the fly-through (smoke.json has 4 path frames: the playback loops).
    std::string out;
    int rc = runGui(gui + " " + kSmoke + " --algorithm psv --set stack_size=64 --set ray_offset=0.0002 --play" +
                        " --frames 6 --screenshot " + shot + " --report " + report,
                    out);
    ASSERT_EQ(rc, 0) << out;

    Json r = readJson(report);
    EXPECT_EQ(r["algorithm"], "psv");
    EXPECT_EQ(r["params"]["stack_size"], 64);
    EXPECT_DOUBLE_EQ(r["params"]["ray_offset"].get<double>(), 0.0002);
    for (const Json& f : r["frames"]) EXPECT_EQ(f["algorithm"], "psv");
    ASSERT_EQ(r["frames"].size(), 6u);
    // Playback advanced through the path: frames 0..3, then wrapped.
    std::vector<int> pathFrames;
    for (const Json& f : r["frames"]) pathFrames.push_back(f["path_frame"].get<int>());
    EXPECT_EQ(pathFrames, (std::vector<int>{0, 1, 2, 3, 0, 1}));
    EXPECT_NE(vec3(r["frames"][0]["camera"]["position"]), vec3(r["frames"][1]["camera"]["position"]));

    Png png(shot);
    ASSERT_TRUE(png.ok()) << shot;
    ASSERT_EQ(png.width(), 1280);
    ASSERT_EQ(png.height(), 800);

    std::set<int> colours;
    size_t blue = 0, dark = 0, panel = 0;
    for (int y = 0; y < png.height(); ++y)
        for (int x = 0; x < kPanelWidth; ++x, ++panel) {
            Rgb c = png.at(x, y);
            colours.insert((c.r << 16) | (c.g << 8) | c.b);
            if (c.b > c.r + 40 && c.b > 60) ++blue;
            if (c.max() < 40) ++dark;
        }
    EXPECT_GE(colours.size(), kMinPanelColours);
    EXPECT_GE(double(blue) / double(panel), kMinPanelBlue);
    EXPECT_GE(double(dark) / double(panel), kMinPanelDark);

    size_t lit = 0, shadowed = 0, scene = 0;
    for (int y = 0; y < png.height(); ++y)
        for (int x = kPanelWidth + 8; x < png.width(); ++x, ++scene) {
            Rgb c = png.at(x, y);
            // The ground and fence are neutral grey; the sky is blue, the sphere red, the torus blue.
            bool neutral = std::abs(c.r - c.g) < 12 && std::abs(c.g - c.b) < 25;
            if (!neutral) continue;
            if (c.max() >= 170) ++lit;
            else if (c.max() >= 60 && c.max() < 130) ++shadowed;
        }
    EXPECT_GE(double(lit) / double(scene), kMinLitGround) << lit << " lit of " << scene;
    EXPECT_GE(double(shadowed) / double(scene), kMinShadowedGround) << shadowed << " shadowed of " << scene;
}

TEST(GuiTest, RecordedPathRunsUnchangedAndReproducesTheCamera) {
    REQUIRE_GUI(gui);
    std::string dir = test::makeTempDir("guipath");
    std::string saved = dir + "/recorded.json", report = dir + "/report.json";
    const std::vector<std::pair<glm::vec3, glm::vec3>> keys = {
        {{0, 3, 5}, {0, 0.4f, 0}}, {{3, 2.5f, 3.5f}, {0, 0.4f, 0}}, {{-2, 2, 4}, {0, 0.5f, 0}}};
    std::string text;
    for (const auto& [p, t] : keys) {
        std::ostringstream os;
        os << p.x << "," << p.y << "," << p.z << "," << t.x << "," << t.y << "," << t.z << ";";
        text += os.str();
    }
    // Record the keyframes as the button does, save, then play the recording and log every camera.
    std::string out;
    int rc = runGui(gui + " " + kSmoke + " --set bias_slope=2.5 --record-keyframes \"" + text +
                        "\" --record-step 0.5 --save-config " + saved + " --play --frames 5 --report " + report,
                    out);
    ASSERT_EQ(rc, 0) << out;
    ASSERT_TRUE(fs::exists(saved)) << out;

    // The saved file is an ordinary experiment: `shadowlab run` accepts it unchanged.
    std::string results = dir + "/results";
    rc = test::runCommand(std::string(SHADOWLAB_BINARY) + " run " + saved + " --no-progress --out " + results, out);
    ASSERT_EQ(rc, 0) << out;
    Json resolved = readJson(results + "/config.resolved.json");
    const Json& kf = resolved["camera"]["path"]["keyframes"];
    ASSERT_EQ(kf.size(), keys.size());
    for (size_t i = 0; i < keys.size(); ++i) {
        EXPECT_DOUBLE_EQ(kf[i]["time"].get<double>(), 0.5 * double(i));
        EXPECT_EQ(vec3(kf[i]["position"]), keys[i].first) << "keyframe " << i;
        EXPECT_EQ(vec3(kf[i]["target"]), keys[i].second) << "keyframe " << i;
    }
    EXPECT_EQ(resolved["algorithms"][0]["params"]["bias_slope"], 2.5);

    // The app played the recorded path exactly as the runner samples it (Path::at at frameTime).
    ExperimentConfig cfg = loadConfig(saved, false);
    Json r = readJson(report);
    ASSERT_EQ(r["frames"].size(), 5u);
    for (const Json& f : r["frames"]) {
        int frame = f["path_frame"].get<int>();
        Camera expected = cfg.cameraAt(frame);
        glm::vec3 p = vec3(f["camera"]["position"]), t = vec3(f["camera"]["target"]);
        // Same float arithmetic on both sides; 1e-5 only absorbs the JSON round trip of floats.
        EXPECT_LT(glm::length(p - expected.position), 1e-5f) << "frame " << frame;
        EXPECT_LT(glm::length(t - expected.target), 1e-5f) << "frame " << frame;
    }
}

// Fifteenth probe: with the config given by a relative path, its glTF was saved relative to the
// working directory, and the saved config (in another folder) could not find it.
TEST(GuiTest, ASavedConfigFindsItsGltfFromAnyFolder) {
    REQUIRE_GUI(gui);
    const std::string dir = test::makeTempDir("gui-gltf");
    fs::create_directories(dir + "/cfg");
    fs::create_directories(dir + "/saved");
    std::ofstream(dir + "/cfg/b.gltf") << test::triangleGltf();
    std::ofstream(dir + "/cfg/base.json") << test::configWith(
        {{"scene", R"({"objects": [{"procedural": "plane", "size": [8, 8]}, {"gltf": "b.gltf"}]})"},
         {"light", R"({"type": "point", "position": [2, 4, 1.5]})"}});
    std::string out;
    ASSERT_EQ(runGui("cd " + dir + " && " + gui + " cfg/base.json --size 64x64 --frames 1 --record-keyframes \"0,3,5,0,0,0\" "
                     "--save-config saved/rec.json", out), 0) << out;
    EXPECT_EQ(test::runCommand(std::string(SHADOWLAB_BINARY) + " validate " + dir + "/saved/rec.json", out), 0) << out;
}

TEST(GuiTest, PlaysMovingGeometryOnTheRunnersClock) {
    REQUIRE_GUI(gui);
    // The windmill config: its rotor and torus move on the camera path's clock; the playback (and
    // so the scrubber, which sets the same frame) poses them as `shadowlab run` does.
    const std::string windmill = std::string(SHADOWLAB_SOURCE_DIR) + "/configs/dynamic/windmill.json";
    std::string dir = test::makeTempDir("gui"), report = dir + "/report.json", out;
    int rc = runGui(gui + " " + windmill + " --algorithm psv --frame 3 --play --frames 3 --report " + report, out);
    ASSERT_EQ(rc, 0) << out;
    ExperimentConfig cfg = loadConfig(windmill, false);
    Json r = readJson(report);
    ASSERT_EQ(r["frames"].size(), 3u);
    for (const Json& f : r["frames"]) {
        const int frame = f["path_frame"].get<int>();
        EXPECT_DOUBLE_EQ(f["scene_time"].get<double>(), cfg.sceneTimeAt(frame)) << "frame " << frame;
        EXPECT_TRUE(f["stages"].contains("scene_update")) << "frame " << frame;
    }
    EXPECT_EQ(r["frames"][0]["path_frame"], 3);
    EXPECT_NE(r["frames"][0]["scene_time"], r["frames"][1]["scene_time"]);
}

TEST(GuiTest, BadInputIsOneLineAndExitCode2) {
    if (kGui.empty()) FAIL() << "shadowlab-gui was not built (needs libglfw3-dev and libimgui-dev)";
    // Checked before any window opens, so no X server is needed.
    // Twenty-third probe: a repeated --set was taken (the last one), where shadowlab run refuses it.
    for (const std::string args : {" --set no_such_key=1", " --algorithm no_such_algorithm", " --set resolution=1",
                                   " --frames x", " /nonexistent/config.json", " --algorithm shadow_map --set pcf=0 --set pcf=3",
                                   // Twenty-fourth probe: a positive step too small for a float was "not positive".
                                   " --record-keyframes '0,3,5,0,0,0' --record-step 1e-300"}) {
        std::string out;
        EXPECT_EQ(test::runCommand(kGui + " " + (args[1] == '/' ? "" : kSmoke) + args, out), 2) << args << "\n" << out;
        std::string trimmed = out.substr(0, out.find_last_not_of('\n') + 1);
        EXPECT_EQ(trimmed.find('\n'), std::string::npos) << out;
    }
}

/// The GUI's exit code and one-line error, before any window opens (no X server needed).
int guiError(const std::string& args, std::string& out) {
    int rc = test::runCommand(kGui + " " + args, out);
    return rc;
}

// Fifteenth probe: each of these was read as something (64x64, frame 10, 16, 1) or as no output.
TEST(GuiTest, MalformedNumbersAndEmptyFileNamesAreBadInput) {
    if (kGui.empty()) FAIL() << "shadowlab-gui was not built (needs libglfw3-dev and libimgui-dev)";
    for (const std::string args : {"--size 64x64x", "--size +64x+64", "--size 64xx64", "--resize 64x064", "--frames 0x2",
                                   "--frames 2 --frame 010", "--frames 2 --frame 1e0", "--frames ' 2'", "--render-scale 0x1",
                                   "--render-scale inf", "--frames 1 --screenshot ''", "--frames 1 --report ''",
                                   "--record-keyframes '0,3,5,0,,0,0' --save-config x.json", "--record-keyframes '0,3,5,0,0,0' --save-config ''",
                                   "--record-keyframes '0,3,5,0,0,0;;1,3,5,0,0,0' --save-config x.json",
                                   // Probe 26: names with a line break or a control character, and
                                   // options given twice (the last taken, the first output lost).
                                   "--frames 1 --report \"$(printf 'r\\n.json')\"", "--frames 1 --screenshot \"$(printf 's\\001.png')\"",
                                   "--frames 1 --report r1.json --report r2.json", "--frames 1 --frames 2", "--play --play",
                                   "--view shaded --view heat"}) {
        std::string out;
        EXPECT_EQ(guiError(kSmoke + " " + args, out), 2) << args << "\n" << out;
        EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << args << "\n" << out;
    }
}

// Twentieth probe: the GUI opened what validate refuses (translucent casters under bvh_raytrace, a
// scene past the memory plan, where it died in Mesa under ulimit -v), and --screenshot or
// --report over its own config replaced it. Each is refused before the first frame.
TEST(GuiTest, WhatValidateRefusesAndOutputsOverInputsAreRefusedBeforeAFrame) {
    REQUIRE_GUI(cmd);
    const std::string dir = test::makeTempDir("gui-refusals");
    std::ofstream(dir + "/glass.json") << test::configWith(
        {{"scene", R"({"objects": [{"procedural": "plane"}, {"procedural": "sphere", "material": {"opacity": 0.5}}]})"},
         {"algorithms", R"([{"algorithm": "bvh_raytrace"}])"}});
    std::string out;
    // An algorithm's fit on the scene asks the device, so this one is refused once the context exists.
    EXPECT_EQ(runGui(cmd + " " + dir + "/glass.json --frames 1 2>&1", out), 2) << out;
    EXPECT_NE(out.find("translucent"), std::string::npos) << out;
    std::ofstream(dir + "/c.json") << test::configWith({});
    auto text = [](const std::string& path) { std::ifstream in(path); return std::string(std::istreambuf_iterator<char>(in), {}); };
    const std::string original = text(dir + "/c.json");
    for (const std::string option : {"--screenshot", "--report"}) {
        EXPECT_EQ(guiError(dir + "/c.json --frames 1 " + option + " " + dir + "/c.json", out), 2) << out;
        EXPECT_NE(out.find("an input of this session"), std::string::npos) << out;
    }
    EXPECT_EQ(text(dir + "/c.json"), original);
    // Twenty-fourth probe: --report R/summary.json turned a run's summary into a frame log, and
    // --screenshot and --report naming one file kept the last one written. Both before a window.
    fs::create_directories(dir + "/run");
    std::ofstream(dir + "/run/summary.json") << "{}";
    std::ofstream(dir + "/run/.shadowlab-output");
    EXPECT_EQ(guiError(dir + "/c.json --frames 1 --report " + dir + "/run/summary.json", out), 2) << out;
    EXPECT_NE(out.find("--report"), std::string::npos) << out;
    EXPECT_EQ(text(dir + "/run/summary.json"), "{}");
    EXPECT_EQ(guiError(dir + "/c.json --frames 1 --screenshot " + dir + "/same.png --report " + dir + "/same.png", out), 2) << out;
    EXPECT_NE(out.find("name the same file"), std::string::npos) << out;
    // Twenty-third probe: a line_space pool validate refuses, asked for with --set, failed in the
    // build with exit 1; it is refused before the first frame, as validate refuses it.
    EXPECT_EQ(runGui(cmd + " " + dir + "/c.json --frames 1 --size 64x64 --algorithm line_space --set n=8 --set d=4 2>&1", out), 2) << out;
    EXPECT_NE(out.find("line_space"), std::string::npos) << out;
#if !defined(__SANITIZE_ADDRESS__)
    std::ofstream(dir + "/big.json") << test::configWith(
        {{"scene", R"({"objects": [{"procedural": "soup", "triangles": 8000000}]})"}});
    EXPECT_EQ(test::runCommand("(ulimit -v 1500000; " + kGui + " " + dir + "/big.json --frames 1)", out), 2) << out;
    EXPECT_NE(out.find("(ulimit -v)"), std::string::npos) << out;
#endif
}

// Nineteenth probe: --help and --version exited 0 with nothing written.
TEST(GuiTest, HelpAndVersionToAFullOrClosedOutputAreAnError) {
    if (kGui.empty()) FAIL() << "shadowlab-gui was not built (needs libglfw3-dev and libimgui-dev)";
    for (const std::string args : {"--help > /dev/full", "--version > /dev/full", "--help >&-", "--version >&-"}) {
        std::string out;
        EXPECT_EQ(test::runCommand("(" + kGui + " " + args + ")", out), 2) << args << "\n" << out;
        EXPECT_NE(out.find("shadowlab-gui: error: standard output"), std::string::npos) << args << "\n" << out;
    }
}

TEST(GuiTest, HelpExitsZeroWhateverElseTheLineHolds) {
    if (kGui.empty()) FAIL() << "shadowlab-gui was not built (needs libglfw3-dev and libimgui-dev)";
    for (const std::string args : {"--help", "-h", "--help --frames x", "--size 1x1 --help"}) {
        std::string out;
        EXPECT_EQ(guiError(args, out), 0) << args << "\n" << out;
        EXPECT_NE(out.find("Usage:"), std::string::npos) << args << "\n" << out;
    }
}

TEST(GuiTest, EchoedValuesStayShort) {
    if (kGui.empty()) FAIL() << "shadowlab-gui was not built (needs libglfw3-dev and libimgui-dev)";
    const std::string huge(5000, 'v');
    for (const std::string args : {"--view " + huge, "--frames " + huge, "--" + huge, "--report /nonexistent/" + huge + "/r.json"}) {
        std::string out;
        EXPECT_EQ(guiError(kSmoke + " " + args, out), 2) << out.substr(0, 300);
        EXPECT_LT(out.size(), 500u) << out.substr(0, 300);
        EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << out.substr(0, 300);
    }
}

// Sixteenth probe: the GUI printed escape sequences, bidi controls and a value cut inside a UTF-8
// character to the terminal, where the runner masks them.
TEST(GuiTest, ErrorLinesMaskControlCharactersAndStayValidUtf8) {
    if (kGui.empty()) FAIL() << "shadowlab-gui was not built (needs libglfw3-dev and libimgui-dev)";
    std::string longUtf8;
    for (int i = 0; i < 100; ++i) longUtf8 += "\xc3\xa9";  // é, two bytes each
    for (const std::string value : {std::string("\x1b[31mRED\x07"), std::string("a\xe2\x80\xae" "b"), longUtf8}) {
        std::string out;
        EXPECT_EQ(guiError(kSmoke + " --view '" + value + "'", out), 2) << out;
        EXPECT_EQ(out.find('\x1b'), std::string::npos) << out;
        EXPECT_EQ(out.find('\x07'), std::string::npos) << out;
        EXPECT_EQ(out.find("\xe2\x80\xae"), std::string::npos) << out;
        EXPECT_TRUE(isValidUtf8(out)) << out;
    }
}

TEST(GuiTest, WindowSizesBeyondWhatX11AndGlCanMakeAreBadInput) {
    if (kGui.empty()) FAIL() << "shadowlab-gui was not built (needs libglfw3-dev and libimgui-dev)";
    // 100000² used to end in an Xlib abort once the window was asked for.
    for (const std::string args : {"--size 100000x100000", "--size 8193x600", "--resize 640x40000", "--size 10x10"}) {
        std::string out;
        EXPECT_EQ(guiError(kSmoke + " " + args + " --frames 1", out), 2) << args << "\n" << out;
        EXPECT_NE(out.find("64 to 8192"), std::string::npos) << args << "\n" << out;  // 10x10: below the minimum
        EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << out;
    }
}

TEST(GuiTest, OutputFilesOntoAFolderALinkOrADeviceAreRefusedAndLeftAsTheyWere) {
    if (kGui.empty()) FAIL() << "shadowlab-gui was not built (needs libglfw3-dev and libimgui-dev)";
    std::string dir = test::makeTempDir("gui-outputs"), out;
    fs::create_directories(dir + "/folder");
    std::ofstream(dir + "/real.json") << "precious";
    fs::create_symlink(dir + "/real.json", dir + "/link.json");
    const std::string keys = " --record-keyframes \"0,3,5,0,0.4,0\" --frames 1";
    EXPECT_EQ(guiError(kSmoke + keys + " --save-config " + dir + "/folder", out), 2) << out;
    EXPECT_NE(out.find("--save-config: the path is a directory"), std::string::npos) << out;
    EXPECT_EQ(guiError(kSmoke + keys + " --save-config " + dir + "/link.json", out), 2) << out;
    EXPECT_NE(out.find("is a symbolic link"), std::string::npos) << out;
    EXPECT_EQ(guiError(kSmoke + " --frames 1 --report " + dir + "/link.json", out), 2) << out;
    EXPECT_EQ(guiError(kSmoke + " --frames 1 --report /dev/full", out), 2) << out;
    EXPECT_NE(out.find("is a character device"), std::string::npos) << out;
    EXPECT_EQ(guiError(kSmoke + " --frames 1 --screenshot " + dir + "/link.json", out), 2) << out;
    EXPECT_EQ(guiError(kSmoke + " --frames 1 --screenshot " + dir + "/no/such/shot.png", out), 2) << out;
    EXPECT_NE(out.find("does not exist"), std::string::npos) << out;
    // All as they were, and nothing beside them (no folder.tmp, no link.json.tmp-PID).
    EXPECT_TRUE(fs::is_directory(dir + "/folder"));
    EXPECT_TRUE(fs::is_symlink(fs::symlink_status(dir + "/link.json")));
    EXPECT_TRUE(fs::is_character_file("/dev/full"));
    std::set<std::string> names;
    for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
    EXPECT_EQ(names, (std::set<std::string>{"folder", "real.json", "link.json"}));
    std::ifstream in(dir + "/real.json");
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), "precious");
}

TEST(GuiTest, AMovingObjectWithANonFinitePoseIsRefusedNotShownVanished) {
    if (kGui.empty()) FAIL() << "shadowlab-gui was not built (needs libglfw3-dev and libimgui-dev)";
    std::string dir = test::makeTempDir("gui-pose"), out;
    std::ofstream(dir + "/c.json") << R"({"frames": 2, "resolution": [16, 16],
        "scene": {"time_range": [0, 1.5], "objects": [{"procedural": "plane"},
          {"procedural": "sphere", "path": {"keyframes": [{"time": 0, "scale": 1}, {"time": 1, "scale": 3.4e38},
            {"time": 2, "scale": 3.4e38}, {"time": 3, "scale": 1}]}}]},
        "algorithms": [{"algorithm": "shadow_map"}]})";
    EXPECT_EQ(guiError(dir + "/c.json --frames 1", out), 2) << out;
    EXPECT_NE(out.find("/scene/objects/1/path"), std::string::npos) << out;
    EXPECT_NE(out.find("frame 1"), std::string::npos) << out;
}

} // namespace
} // namespace shadowlab
