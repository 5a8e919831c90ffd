#pragma once
// Error types that map to the CLI's exit codes: bad input (2) and runtime failure (1).
#include <stdexcept>
#include <string>

namespace shadowlab {

/// Bad input: a config, scene file or parameter that cannot be used. Exit code 2.
/// The message is one line: "FILE: at JSON_PATH: CAUSE" (path omitted when not applicable).
class InputError : public std::runtime_error {
public:
    InputError(const std::string& file, const std::string& jsonPath, const std::string& cause)
        : std::runtime_error(format(file, jsonPath, cause)), file_(file), path_(jsonPath), cause_(cause) {}

    const std::string& file() const { return file_; }
    const std::string& jsonPath() const { return path_; }
    const std::string& cause() const { return cause_; }

private:
    static std::string format(const std::string& file, const std::string& path, const std::string& cause) {
        std::string s = file.empty() ? std::string("<input>") : cut(file, 300);
        if (!path.empty()) s += ": at " + cut(path, 200);
        return s + ": " + cut(cause, 300);
    }
    /// One short line whatever the input echoed into it: newlines become "; ", long text is cut.
    static std::string cut(const std::string& text, size_t maxChars) {
        std::string out;
        for (char c : text) {
            if (out.size() >= maxChars) return out + "...";
            if (c == '\n') out += "; ";
            else if (c == '\0') out += '?'; // what() is a C string: a NUL would end the line there
            else if (c != '\r') out += c;
        }
        return out;
    }
    std::string file_, path_, cause_;
};

/// Something failed while running (GL error, out of memory, I/O). Exit code 1.
class RuntimeError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// An algorithm cannot hold this scene with these parameter values on this device (a pool past
/// what a storage block addresses): an input problem found only once the scene exists. The runner
/// and `validate` report it at the algorithm's entry in the config (exit 2), never as a failure.
class SceneRefusal : public RuntimeError {
public:
    using RuntimeError::RuntimeError;
};

} // namespace shadowlab
