// shadowlab-gui: the interactive viewer (GLFW window + Dear ImGui) over the same framework as `shadowlab`.
#include "framework/core/Error.h"
#include "framework/core/StandardStreams.h"
#include "framework/core/Text.h"
#include "framework/gui/GuiApp.h"

#include <csignal>
#include <cstdio>
#include <string>
#include <vector>

using namespace shadowlab;

namespace {

/// One line of at most 400 characters, whatever a failure's message echoes (a path, a GL log).
std::string oneLine(const char* text) {
    std::string out;
    for (const char* c = text; *c && out.size() < 400; ++c) out += *c == '\n' ? ' ' : *c;
    return *text && std::string(text).size() > 400 ? out + "..." : out;
}

} // namespace

static int guiMain(int argc, char** argv);

// Nineteenth probe: --help and --version exited 0 with standard output full or closed, where
// shadowlab reports it (exit 2), as docs/getting_started.md says the two do alike.
int main(int argc, char** argv) {
    reopenClosedStandardStreams();
    std::signal(SIGPIPE, SIG_IGN);  // a reader gone is a write error reported, not a silent death
    return checkStandardOutput("shadowlab-gui", guiMain(argc, argv));
}

static int guiMain(int argc, char** argv) {
    try {
        GuiOptions opts = parseGuiOptions(std::vector<std::string>(argv + 1, argv + argc));
        if (opts.help) {
            std::fputs(kGuiUsage, stdout);
            return 0;
        }
        if (opts.version) {
            std::puts("shadowlab-gui 0.1");
            return 0;
        }
        return runGui(opts);
    } catch (const InputError& e) {
        // Masked and bounded as the runner's (sixteenth probe: escape sequences and bidi controls
        // in a value or a config path reached the terminal raw).
        std::fprintf(stderr, "shadowlab-gui: error: %s\n", shortText(e.what(), 1000).c_str());
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "shadowlab-gui: failed: %s\n", shortText(oneLine(e.what()), 1000).c_str());
        return 1;
    }
}
