#include "framework/core/StandardStreams.h"

#include "framework/core/Error.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>

namespace shadowlab {

void reopenClosedStandardStreams() {
    for (int fd : {0, 1, 2})
        if (fcntl(fd, F_GETFD) < 0 && errno == EBADF) {
            const int opened = open(fd == 1 ? "/dev/full" : "/dev/null", fd == 0 ? O_RDONLY : O_WRONLY);
            if (opened >= 0 && opened != fd) {
                dup2(opened, fd);
                close(opened);
            }
        }
}

namespace {
bool failureReported = false; ///< writeStandardOutput() already said the stream cannot be written
} // namespace

void writeStandardOutput(const std::string& text) {
    std::cout << text;
    std::cout.flush();
    if (std::cout) return;
    failureReported = true;
    throw InputError("standard output", "", "cannot be written (a full disk or a closed stream)");
}

int checkStandardOutput(const char* program, int rc) {
    std::cout.flush();
    errno = 0;
    if (std::fflush(stdout) == 0 && !std::ferror(stdout) && std::cout.good()) return rc;
    if (failureReported) return rc == 0 ? 2 : rc;
    std::fprintf(stderr, "%s: error: standard output: cannot write what the command printed (%s)\n", program,
                 errno ? std::strerror(errno) : "write error");
    return rc == 0 ? 2 : rc;
}

} // namespace shadowlab
