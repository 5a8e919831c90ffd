#include "framework/gui/GuiOptions.h"

#include "framework/core/Error.h"
#include "framework/core/FileIO.h"
#include "framework/core/Text.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <set>

namespace shadowlab {

const char* const kGuiUsage = R"(shadowlab-gui: interactive viewer of the shadow algorithms (GLFW + Dear ImGui).

Usage:
  shadowlab-gui [CONFIG.json] [options]
      Opens the config's scene, light, camera path and algorithms (a built-in scene without one).

Automation (tests, docs; each acts through the same code as the widgets):
  --algorithm ID            start with this config entry id or registered algorithm
  --set KEY=VALUE           set a parameter of that algorithm (repeatable); VALUE as JSON or a bare string, as in shadowlab run
  --view MODE               shaded | visibility | heat | difference
  --reference               trace the CPU reference after the first frame (for the difference view)
  --play                    play the fly-through;  --frame N  start at frame N
  --frames N                exit after N rendered frames (default: run until the window closes)
  --screenshot FILE.png     write the whole window after the last frame
  --record-keyframes "x,y,z,tx,ty,tz;..."   record these camera poses, as the Add keyframe button
  --record-step S           path seconds between recorded keyframes
  --save-config FILE.json   save the recorded path and current settings as an experiment config
  --report FILE.json        log every rendered frame (camera, light, stage times)
  --size WxH                window size (default 1280x800; 64-8192 per side);  --render-scale S  (0.125-1)
  --resize WxH              resize the window after the first frame (64-8192 per side)

Exit codes: 0 success, 2 bad input (one line), 1 runtime failure. F1 in the window lists the keys.
)";

namespace {

InputError usage(const std::string& cause) { return InputError("command line", "", cause + " (see --help)"); }

/// What the user typed, echoed back at most 60 characters long (a pasted file stays one short line).
std::string echoed(const std::string& text) {
    return "\"" + shortText(text, 57) + "\"";
}

/// A plain decimal number (sign, digits, fraction, exponent), as the runner's --threshold: strtod's
/// hex, inf and leading spaces are refused (fifteenth probe: `0x10` was read as 16).
double number(const std::string& opt, const std::string& text) {
    const double v = plainDecimal(text) ? std::strtod(text.c_str(), nullptr) : NAN;
    if (!std::isfinite(v)) throw usage(opt + " expects a number, got " + echoed(text));
    return v;
}

/// Decimal digits only, without a leading zero (`010`, `+5`, `1e0`, `0x2` refused: each was read as
/// some number before), as the runner's counts.
int integer(const std::string& opt, const std::string& text, int minValue) {
    const bool digits = !text.empty() && text.size() <= 9 && text.find_first_not_of("0123456789") == std::string::npos &&
                        (text.size() == 1 || text[0] != '0');
    const int v = digits ? std::stoi(text) : -1;
    if (v < minValue) throw usage(opt + " expects a whole number >= " + std::to_string(minValue) + " in decimal digits, got " + echoed(text));
    return v;
}

/// The fields of `s` between each `sep`, empty ones kept (`64x64x` has three fields, `1,,2` an
/// empty one: both refused by their callers rather than read as something else).
std::vector<std::string> split(const std::string& s, char sep) {
    std::vector<std::string> out;
    size_t at = 0;
    for (size_t next; (next = s.find(sep, at)) != std::string::npos; at = next + 1) out.push_back(s.substr(at, next - at));
    out.push_back(s.substr(at));
    return out;
}

std::vector<std::pair<glm::vec3, glm::vec3>> parseKeyframes(const std::string& text) {
    std::vector<std::pair<glm::vec3, glm::vec3>> out;
    std::vector<std::string> keys = split(text, ';');
    if (keys.size() > 1 && keys.back().empty()) keys.pop_back();  // "k1;k2;" ends its last keyframe
    for (const std::string& key : keys) {
        std::vector<std::string> f = split(key, ',');
        if (f.size() != 6) throw usage("--record-keyframes: " + echoed(key) + " needs 6 numbers x,y,z,tx,ty,tz");
        float v[6];
        for (int i = 0; i < 6; ++i) v[i] = float(number("--record-keyframes", f[size_t(i)]));
        glm::vec3 position(v[0], v[1], v[2]), target(v[3], v[4], v[5]);
        if (position == target) throw usage("--record-keyframes: " + echoed(key) + " looks at its own position");
        out.push_back({position, target});
    }
    if (out.empty()) throw usage("--record-keyframes needs at least one keyframe");
    return out;
}

glm::ivec2 size(const std::string& opt, const std::string& text) {
    std::vector<std::string> wh = split(text, 'x');
    if (wh.size() != 2) throw usage(opt + " expects WxH, got " + echoed(text));
    const glm::ivec2 s(integer(opt, wh[0], 0), integer(opt, wh[1], 0));
    if (s.x < kWindowSideMin || s.y < kWindowSideMin || s.x > kWindowSideMax || s.y > kWindowSideMax)
        throw usage(opt + " " + echoed(text) + ": each side must be " + std::to_string(kWindowSideMin) + " to " +
                    std::to_string(kWindowSideMax));
    return s;
}

/// An output file must be one that can be written as a whole and replaced: a directory, link,
/// device or FIFO there is refused (writeFileAtomic would refuse it only after the whole session).
void checkOutputFile(const std::string& opt, const std::string& file) {
    const std::string shown = shortPath(file);
    if (const std::string kind = nonRegularKind(file, false); !kind.empty())
        throw InputError(shown, "", opt + ": the path is " + kind + ", not a file it can replace");
    const std::filesystem::path parent = std::filesystem::path(file).parent_path();
    std::error_code ec;
    if (!parent.empty() && !std::filesystem::is_directory(parent, ec))
        throw InputError(shown, "", opt + ": the folder " + echoed(parent.string()) + " does not exist");
}

/// An output option's value: an empty one is refused, not taken for "no output" (fifteenth probe:
/// `--screenshot ''` wrote nothing and said nothing).
const std::string& fileName(const std::string& opt, const std::string& value) {
    if (value.empty()) throw usage(opt + " needs a file name");
    // The name as every output's (probe 26: --report and --screenshot made files whose names held
    // a line break or a control character).
    if (const std::string why = pathTextProblem(value); !why.empty()) throw usage(opt + ": the file's path " + why);
    return value;
}

} // namespace

GuiOptions parseGuiOptions(const std::vector<std::string>& args) {
    GuiOptions o;
    // Help is help, whatever else the line holds (a half-typed command, an option it explains).
    for (const std::string& a : args) {
        if (a == "--help" || a == "-h") o.help = true;
        if (a == "--version") o.version = true;
    }
    if (o.help || o.version) return o;
    std::set<std::string> given;
    for (size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        // Twice is a mistake (which was meant?), as for shadowlab's commands (probe 26: the last of
        // two --report was taken, the first never written); --set is checked per key below.
        if (a.starts_with("-") && a != "--set" && !given.insert(a).second) throw usage(a + " is given twice");
        auto value = [&]() -> const std::string& {
            if (i + 1 >= args.size()) throw usage(a + " needs a value");
            return args[++i];
        };
        if (a == "--help" || a == "-h") o.help = true;
        else if (a == "--version") o.version = true;
        else if (a == "--algorithm") o.algorithm = value();
        else if (a == "--set") {
            const std::string& kv = value();
            size_t eq = kv.find('=');
            if (eq == std::string::npos || eq == 0) throw usage("--set expects KEY=VALUE, got " + echoed(kv));
            // As shadowlab run refuses it (twenty-third probe: the GUI took the last of two).
            for (const auto& [key, text] : o.sets)
                if (key == kv.substr(0, eq)) throw usage("--set " + echoed(key) + " is given twice");
            o.sets.push_back({kv.substr(0, eq), kv.substr(eq + 1)});
        } else if (a == "--view") {
            o.view = value();
            if (o.view != "shaded" && o.view != "visibility" && o.view != "heat" && o.view != "difference")
                throw usage("--view expects shaded, visibility, heat or difference, got " + echoed(o.view));
        } else if (a == "--reference") o.reference = true;
        else if (a == "--play") o.play = true;
        else if (a == "--frame") o.startFrame = integer(a, value(), 0);
        else if (a == "--frames") o.frames = integer(a, value(), 1);
        else if (a == "--screenshot") o.screenshot = fileName(a, value());
        else if (a == "--record-keyframes") o.recordKeyframes = parseKeyframes(value());
        else if (a == "--record-step") {
            const double step = number(a, value());
            if (!(step > 0)) throw usage("--record-step must be positive");
            // Read as a float (twenty-fourth probe: 1e-300 became 0 and was called not positive).
            if (!(step >= double(std::numeric_limits<float>::min()) && step <= double(std::numeric_limits<float>::max())))
                throw usage("--record-step is " + echoed(std::to_string(step)) + ", beyond what a float holds");
            o.recordStep = float(step);
        } else if (a == "--save-config") o.saveConfig = fileName(a, value());
        else if (a == "--report") o.report = fileName(a, value());
        else if (a == "--size") o.windowSize = size(a, value());
        else if (a == "--resize") o.resizeTo = size(a, value()); else if (a == "--render-scale") {
            o.renderScale = float(number(a, value()));
            if (o.renderScale < kRenderScaleMin || o.renderScale > kRenderScaleMax)
                throw usage("--render-scale must be in [" + std::to_string(kRenderScaleMin) + ", " +
                            std::to_string(kRenderScaleMax) + "]");
        } else if (!a.empty() && a[0] == '-') throw usage("unknown option " + echoed(a));
        else if (o.config.empty()) o.config = a;
        else throw usage("unexpected argument " + echoed(a));
    }
    if (!o.screenshot.empty() && o.frames == 0) throw usage("--screenshot needs --frames N (it is taken after the last frame)");
    if (!o.saveConfig.empty() && o.recordKeyframes.empty()) throw usage("--save-config needs --record-keyframes");
    if (!o.screenshot.empty()) checkOutputFile("--screenshot", o.screenshot);
    if (!o.report.empty()) checkOutputFile("--report", o.report);
    if (!o.saveConfig.empty()) checkOutputFile("--save-config", o.saveConfig);
    return o;
}

void checkWindowSize(const std::string& option, glm::ivec2 size, int maxViewport, int maxTexture) {
    const int limit = std::min(maxViewport, maxTexture);
    if (limit > 0 && (size.x > limit || size.y > limit))
        throw InputError("command line", "", option + " " + std::to_string(size.x) + "x" + std::to_string(size.y) +
                                                 " exceeds this GL context's limit of " + std::to_string(limit) +
                                                 " pixels per side (GL_MAX_VIEWPORT_DIMS / GL_MAX_TEXTURE_SIZE)");
}

} // namespace shadowlab
