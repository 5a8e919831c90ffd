#include "framework/core/FileIO.h"

#include "framework/core/Error.h"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

namespace shadowlab {

namespace {

const char* kindOf(mode_t m) {
    if (S_ISREG(m)) return "";
    if (S_ISDIR(m)) return "a directory";
    if (S_ISFIFO(m)) return "a FIFO";
    if (S_ISCHR(m)) return "a character device";
    if (S_ISBLK(m)) return "a block device";
    if (S_ISSOCK(m)) return "a socket";
    if (S_ISLNK(m)) return "a symbolic link";
    return "not a regular file";
}

std::string sizeText(size_t bytes) {
    char buf[32];
    // Whole MiB from 1 MiB up; below, bytes (a small cap would read "0 MiB").
    if (bytes < (size_t(1) << 20)) std::snprintf(buf, sizeof buf, "%zu bytes", bytes);
    else std::snprintf(buf, sizeof buf, "%.0f MiB", double(bytes) / double(1 << 20));
    return buf;
}

template <class Buffer>
Buffer readRegular(const std::string& path, size_t maxBytes) {
    // O_NONBLOCK: opening a FIFO must not wait for a writer; the type is checked on the descriptor,
    // so a file swapped for a FIFO between a stat() and the open() cannot slip through.
    const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) throw InputError(path, "", std::string("cannot open file: ") + std::strerror(errno));
    struct stat st {};
    if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        const std::string kind = ::fstat(fd, &st) == 0 ? kindOf(st.st_mode) : "unreadable";
        ::close(fd);
        throw InputError(path, "", "is " + kind + ", not a regular file");
    }
    if (size_t(st.st_size) > maxBytes) {
        ::close(fd);
        throw InputError(path, "", "is larger than " + sizeText(maxBytes) + " (" + sizeText(size_t(st.st_size)) + ")");
    }
    Buffer out;
    out.resize(size_t(st.st_size));
    size_t got = 0;
    for (;;) {
        // A file that grows while it is read is read up to the cap, never beyond.
        if (got == out.size()) {
            if (out.size() >= maxBytes) {
                char probe;
                const ssize_t n = ::read(fd, &probe, 1);
                ::close(fd);
                if (n > 0) throw InputError(path, "", "is larger than " + sizeText(maxBytes));
                return out;
            }
            out.resize(std::min(maxBytes, std::max<size_t>(4096, out.size() * 2)));
        }
        const ssize_t n = ::read(fd, out.data() + got, out.size() - got);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) {
            const int err = errno;
            ::close(fd);
            throw InputError(path, "", std::string("cannot read file: ") + std::strerror(err));
        }
        if (n == 0) break;
        got += size_t(n);
    }
    ::close(fd);
    out.resize(got);
    return out;
}

} // namespace

std::string readInputFile(const std::string& path, size_t maxBytes) { return readRegular<std::string>(path, maxBytes); }

std::vector<unsigned char> readInputFileBytes(const std::string& path, size_t maxBytes) {
    return readRegular<std::vector<unsigned char>>(path, maxBytes);
}

std::string shortPath(const std::string& path) {
    if (path.size() <= 160) return path;
    return path.substr(0, 70) + "..." + path.substr(path.size() - 87);
}

std::string nonRegularKind(const std::string& path, bool followLinks) {
    struct stat st {};
    if ((followLinks ? ::stat(path.c_str(), &st) : ::lstat(path.c_str(), &st)) != 0) return "";
    return kindOf(st.st_mode);
}

void writeFileAtomic(const std::string& path, const std::string& text) {
    const std::string kind = nonRegularKind(path, false);
    if (!kind.empty()) throw InputError(path, "", "is " + kind + ": refusing to replace it with a file");
    const std::string tmp = path + ".tmp-" + std::to_string(::getpid());
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (fd < 0) throw RuntimeError("cannot write " + path + " (creating " + tmp + "): " + std::strerror(errno));
    auto fail = [&](const char* what, int err) {
        ::unlink(tmp.c_str());
        throw RuntimeError(std::string("cannot ") + what + " " + path + ": " + std::strerror(err));
    };
    size_t done = 0;
    while (done < text.size()) {
        const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            const int err = n < 0 ? errno : ENOSPC;
            ::close(fd);
            fail("write", err);
        }
        done += size_t(n);
    }
    if (::fsync(fd) != 0) {
        const int err = errno;
        ::close(fd);
        fail("flush", err);
    }
    if (::close(fd) != 0) fail("close", errno);
    // Checked again just before the rename: a link or FIFO put there meanwhile is not replaced.
    const std::string late = nonRegularKind(path, false);
    if (!late.empty()) {
        ::unlink(tmp.c_str());
        throw InputError(path, "", "is " + late + ": refusing to replace it with a file");
    }
    if (std::rename(tmp.c_str(), path.c_str()) != 0) fail("rename a temporary file to", errno);
}

bool diskNearlyFull(const std::string& dir) {
    struct statvfs disk {};
    return ::statvfs(dir.c_str(), &disk) == 0 && uint64_t(disk.f_bavail) * uint64_t(disk.f_frsize) < (uint64_t(1) << 20);
}

} // namespace shadowlab
