#include "framework/core/JsonParse.h"

#include <vector>

namespace shadowlab {
namespace {

/// Builds the DOM like nlohmann's own SAX-DOM parser, tracking the JSON path of the value being
/// read so that every error names where it is.
class StrictSax : public nlohmann::json_sax<Json> {
public:
    StrictSax(const std::string& file, const JsonLimits& limits) : file_(file), limits_(limits) {}

    Json result;
    std::string errorPath, errorCause;

    bool null() override { return value(nullptr); }
    bool boolean(bool v) override { return value(v); }
    bool number_integer(number_integer_t v) override { return value(v); }
    bool number_unsigned(number_unsigned_t v) override { return value(v); }
    bool number_float(number_float_t v, const string_t& text) override {
        // A number too small for a double is read as 0 (twentieth probe: fit_size 1e-400 turned
        // the fitting off silently): refused, as one too large is.
        if (v == 0.0 && text.substr(0, text.find_first_of("eE")).find_first_of("123456789") != string_t::npos)
            return error(path(), "the number " + cut(text) + " is too small for a double (it would be read as 0)");
        return value(v);
    }
    bool string(string_t& v) override { return value(std::move(v)); }
    bool binary(binary_t& v) override { return value(Json::binary(std::move(v))); }

    bool start_object(std::size_t) override { return open(Json::object()); }
    bool start_array(std::size_t) override { return open(Json::array()); }
    bool end_object() override { return close(); }
    bool end_array() override { return close(); }

    bool key(string_t& k) override {
        Frame& f = frames_.back();
        if (limits_.rejectDuplicateKeys && f.node->contains(k))
            return error(path(false) + "/" + escape(k), "duplicate key \"" + cut(k) + "\" (each key may appear once in an object)");
        f.key = std::move(k);
        f.keyPending = true;
        return true;
    }

    bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception& ex) override {
        // nlohmann's messages start with "[json.exception.parse_error.101] "; keep the useful part.
        std::string msg = ex.what();
        auto pos = msg.find("] ");
        msg = pos == std::string::npos ? msg : msg.substr(pos + 2);
        if (msg.size() > 200) msg = msg.substr(0, 197) + "...";
        if (ex.id == 406) msg = "number does not fit in a double: " + msg;
        return error(frames_.empty() ? "" : path(), "invalid JSON: " + msg);
    }

private:
    struct Frame {
        Json* node;
        std::string key;   // objects: the key whose value comes next (or came last)
        size_t index = 0;  // arrays: the index of the next element
        bool keyPending = false; // objects: `key` was read and its value not yet placed
    };

    static std::string escape(const std::string& key) {  // JSON pointer (RFC 6901)
        std::string out;
        for (char c : key) out += c == '~' ? std::string("~0") : c == '/' ? std::string("~1") : std::string(1, c);
        return cut(out);
    }
    static std::string cut(const std::string& s) { return s.size() > 60 ? s.substr(0, 57) + "..." : s; }

    /// The path of the value being read: through each open container's current slot. An enclosing
    /// array's index was advanced when the open child was placed, so its slot is index - 1; the
    /// innermost array's slot is the next element. `innermostSlot` false: the innermost container,
    /// and so too where an object's last value is read and its next key not (probe 25: a syntax
    /// error after "frames": 1 was reported at /frames, a value that was fine).
    std::string path(bool innermostSlot = true) const {
        std::string p;
        for (size_t i = 0; i < frames_.size(); ++i) {
            const Frame& f = frames_[i];
            bool innermost = i + 1 == frames_.size();
            if (innermost && (!innermostSlot || (f.node->is_object() && !f.keyPending))) break;
            p += "/" + (f.node->is_array() ? std::to_string(innermost ? f.index : f.index - 1) : escape(f.key));
        }
        return p;
    }

    bool error(const std::string& at, const std::string& cause) {
        if (errorCause.empty()) {
            errorPath = at;
            errorCause = cause;
        }
        return false;
    }

    /// Places a value where the parser stands; returns where it now lives.
    Json* place(Json&& v) {
        if (frames_.empty()) {
            result = std::move(v);
            return &result;
        }
        Frame& f = frames_.back();
        if (f.node->is_array()) {
            f.node->push_back(std::move(v));
            ++f.index;
            return &f.node->back();
        }
        Json& slot = (*f.node)[f.key];
        slot = std::move(v);
        f.keyPending = false;
        return &slot;
    }

    bool count() {
        if (++values_ > limits_.maxValues)
            return error(path(), "more than " + std::to_string(limits_.maxValues) + " values (the limit for this file)");
        return true;
    }

    bool value(Json&& v) {
        if (!count()) return false;
        place(std::move(v));
        return true;
    }

    bool open(Json&& container) {
        if (!count()) return false;
        if (int(frames_.size()) >= limits_.maxDepth)
            return error(path(), "nesting deeper than " + std::to_string(limits_.maxDepth) + " levels");
        Json* node = place(std::move(container));
        frames_.push_back({node, {}, 0, false});
        return true;
    }

    bool close() {
        frames_.pop_back();
        // The closed container is an element of its parent array: the parent's index was advanced
        // when the container was placed, so nothing more to do.
        return true;
    }

    const std::string& file_;
    const JsonLimits& limits_;
    std::vector<Frame> frames_;
    size_t values_ = 0;
};

} // namespace

Json parseJson(const std::string& text, const std::string& file, const JsonLimits& limits) {
    // nlohmann's lexer ends the input at a NUL byte (twelfth probe: a config, sweep file, glTF or
    // summary.json with a NUL and garbage after it was read up to the NUL and accepted).
    if (const size_t nul = text.find('\0'); nul != std::string::npos)
        throw InputError(file, "", "holds a NUL byte at byte " + std::to_string(nul) + " (JSON is text; the file is cut or not JSON)");
    StrictSax sax(file, limits);
    bool ok = Json::sax_parse(text, &sax, nlohmann::detail::input_format_t::json, true, false);
    if (!ok || !sax.errorCause.empty())
        throw InputError(file, sax.errorPath, sax.errorCause.empty() ? "invalid JSON" : sax.errorCause);
    return std::move(sax.result);
}

std::string shortDump(const Json& value, size_t maxChars) {
    // dump() of a huge value is itself the cost we avoid: print containers element by element.
    std::string out;
    auto append = [&](const std::string& s) { out += s; return out.size() < maxChars; };
    if (value.is_array() || value.is_object()) {
        bool array = value.is_array();
        append(array ? "[" : "{");
        bool first = true;
        for (auto it = value.begin(); it != value.end(); ++it) {
            std::string item = (first ? "" : ",") + (array ? "" : Json(it.key()).dump() + ":");
            first = false;
            // Nested containers print short too, so the whole stays bounded whatever the depth.
            if (!append(item + shortDump(*it, maxChars))) break;
        }
        if (out.size() < maxChars) append(array ? "]" : "}");
    } else {
        out = value.dump();
    }
    return out.size() > maxChars ? out.substr(0, maxChars - 3) + "..." : out;
}

} // namespace shadowlab
