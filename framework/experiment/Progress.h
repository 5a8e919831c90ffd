#pragma once
// A progress bar on stderr: redrawn in place on a terminal, a line per 10 % otherwise (CI logs).
#include <chrono>
#include <cstdio>
#include <string>
#include <unistd.h>

namespace shadowlab {

class Progress {
public:
    Progress(bool enabled, size_t total) : enabled_(enabled), total_(total ? total : 1), tty_(isatty(2)) {}

    void step(const std::string& label) {
        if (!enabled_) return;
        ++done_;
        double f = double(done_ - 1) / double(total_);
        if (tty_) {
            int filled = int(f * 30);
            std::fprintf(stderr, "\r[%-30s] %3d%%  %-40.40s", std::string(size_t(filled), '#').c_str(), int(f * 100), label.c_str());
            std::fflush(stderr);
        } else if (int(f * 10) > lastDecile_) {
            lastDecile_ = int(f * 10);
            std::fprintf(stderr, "progress %3d%%  %s\n", lastDecile_ * 10, label.c_str());
        }
    }
    void finish() {
        if (!enabled_) return;
        if (tty_) std::fprintf(stderr, "\r[%-30s] 100%%  %-40s\n", std::string(30, '#').c_str(), "done");
        else std::fprintf(stderr, "progress 100%%  done\n");
    }

private:
    bool enabled_;
    size_t total_, done_ = 0;
    bool tty_;
    int lastDecile_ = -1;
};

} // namespace shadowlab
