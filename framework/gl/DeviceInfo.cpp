#include "framework/gl/DeviceInfo.h"

#include "framework/core/FileIO.h"
#include "framework/gl/Gl.h"
#include "framework/gl/GlContext.h"
#include "framework/gl/Shader.h"

#include <algorithm>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>

namespace shadowlab {
namespace {

/// A limit the project depends on and how many values it has (indexed ones are read per index).
struct LimitQuery {
    const char* name;
    GLenum pname;
    int count;    ///< 1: glGetInteger64v; 2: glGetIntegerv into two values; 3: glGetIntegeri_v for 0..2
};

// Storage blocks (every structure is an SSBO; ptsv and line_space size theirs against the block
// limit), buffer textures (every kernel's read-only view, framework/gl/GlObjects.h), compute
// dispatch (dispatchLinear's 2D grids, the traversal workgroups, metric_tree's shared candidate
// lists), the texture units the scene and ptsv bind, and the image sizes of shadow maps and the GUI.
const LimitQuery kLimits[] = {
    {"GL_MAX_SHADER_STORAGE_BLOCK_SIZE", GL_MAX_SHADER_STORAGE_BLOCK_SIZE, 1},
    {"GL_MAX_SHADER_STORAGE_BUFFER_BINDINGS", GL_MAX_SHADER_STORAGE_BUFFER_BINDINGS, 1},
    {"GL_MAX_COMBINED_SHADER_STORAGE_BLOCKS", GL_MAX_COMBINED_SHADER_STORAGE_BLOCKS, 1},
    {"GL_MAX_COMPUTE_SHADER_STORAGE_BLOCKS", GL_MAX_COMPUTE_SHADER_STORAGE_BLOCKS, 1},
    {"GL_MAX_TEXTURE_BUFFER_SIZE", GL_MAX_TEXTURE_BUFFER_SIZE, 1},
    {"GL_MAX_COMPUTE_WORK_GROUP_COUNT", GL_MAX_COMPUTE_WORK_GROUP_COUNT, 3},
    {"GL_MAX_COMPUTE_WORK_GROUP_SIZE", GL_MAX_COMPUTE_WORK_GROUP_SIZE, 3},
    {"GL_MAX_COMPUTE_WORK_GROUP_INVOCATIONS", GL_MAX_COMPUTE_WORK_GROUP_INVOCATIONS, 1},
    {"GL_MAX_COMPUTE_SHARED_MEMORY_SIZE", GL_MAX_COMPUTE_SHARED_MEMORY_SIZE, 1},
    {"GL_MAX_COMPUTE_TEXTURE_IMAGE_UNITS", GL_MAX_COMPUTE_TEXTURE_IMAGE_UNITS, 1},
    {"GL_MAX_COMPUTE_IMAGE_UNIFORMS", GL_MAX_COMPUTE_IMAGE_UNIFORMS, 1},
    {"GL_MAX_TEXTURE_SIZE", GL_MAX_TEXTURE_SIZE, 1},
    {"GL_MAX_CUBE_MAP_TEXTURE_SIZE", GL_MAX_CUBE_MAP_TEXTURE_SIZE, 1},
    {"GL_MAX_VIEWPORT_DIMS", GL_MAX_VIEWPORT_DIMS, 2},
};

/// Extensions the C++ side relies on besides those the shaders name: the debug output every run
/// checks for GL errors (core since 4.3, listed so a driver that lacks it shows).
const char* kHostExtensions[] = {"GL_KHR_debug"};

std::string glString(GLenum name) {
    const GLubyte* s = glGetString(name);
    return s ? reinterpret_cast<const char*>(s) : "unknown";
}

Json readLimit(const LimitQuery& q) {
    if (q.count == 1) {
        GLint64 v = 0;
        glGetInteger64v(q.pname, &v);
        return v;
    }
    if (q.count == 2) {
        GLint v[2] = {0, 0};
        glGetIntegerv(q.pname, v);
        return Json::array({v[0], v[1]});
    }
    Json out = Json::array();
    for (GLuint i = 0; i < 3; ++i) {
        GLint v = 0;
        glGetIntegeri_v(q.pname, i, &v);
        out.push_back(v);
    }
    return out;
}

} // namespace

std::vector<ExtensionUse> shaderExtensions() {
    namespace fs = std::filesystem;
    std::map<std::string, std::set<std::string>> uses;
    const fs::path root = shaderDir();
    std::error_code ec;
    for (fs::recursive_directory_iterator it(root, ec), end; !ec && it != end; it.increment(ec)) {
        if (!it->is_regular_file(ec)) continue;
        std::istringstream in(readInputFile(it->path().string()));
        std::string line;
        while (std::getline(in, line)) {
            const size_t p = line.find_first_not_of(" \t");
            if (p == std::string::npos || line.compare(p, 10, "#extension") != 0) continue;
            std::istringstream words(line.substr(p + 10));
            std::string name;
            if (words >> name && name != "all") uses[name].insert(it->path().lexically_relative(root).generic_string());
        }
    }
    std::vector<ExtensionUse> out;
    for (const auto& [name, files] : uses) out.push_back({name, std::vector<std::string>(files.begin(), files.end())});
    return out;
}

Json deviceRecord(const std::string& backend) {
    Json limits = Json::object();
    for (const LimitQuery& q : kLimits) limits[q.name] = readLimit(q);
    Json extensions = Json::object();
    for (const ExtensionUse& e : shaderExtensions()) extensions[e.name] = hasExtension(e.name.c_str());
    for (const char* name : kHostExtensions) extensions[name] = hasExtension(name);
    return {{"vendor", glString(GL_VENDOR)},
            {"renderer", glString(GL_RENDERER)},
            {"version", glString(GL_VERSION)},
            {"glsl_version", glString(GL_SHADING_LANGUAGE_VERSION)},
            {"backend", backend},
            {"subgroup_size", querySubgroupSize()},
            {"limits", limits},
            {"extensions", extensions}};
}

bool isByteLimit(const std::string& name) {
    return name == "GL_MAX_SHADER_STORAGE_BLOCK_SIZE" || name == "GL_MAX_COMPUTE_SHARED_MEMORY_SIZE";
}

} // namespace shadowlab
