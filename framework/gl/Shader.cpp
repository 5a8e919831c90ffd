#include "framework/gl/Shader.h"

#include "framework/core/Error.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>

#ifndef SHADOWLAB_SHADER_DIR
#error "SHADOWLAB_SHADER_DIR must be defined by the build"
#endif

namespace shadowlab {

std::string shaderDir() {
    if (const char* env = std::getenv("SHADOWLAB_SHADER_DIR"); env && *env) return env;
    return SHADOWLAB_SHADER_DIR;
}

static std::string readFile(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw RuntimeError("cannot read shader file " + path);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

static std::string expandIncludes(const std::string& relPath, std::set<std::string>& seen) {
    if (!seen.insert(relPath).second) return ""; // include once
    std::istringstream in(readFile(shaderDir() + "/" + relPath));
    std::ostringstream out;
    std::string line;
    int lineNo = 0;
    while (std::getline(in, line)) {
        ++lineNo;
        auto p = line.find("#include");
        if (p != std::string::npos && line.find_first_not_of(" \t") == p) {
            auto a = line.find('"'), b = line.rfind('"');
            if (a == std::string::npos || b <= a) throw RuntimeError(relPath + ":" + std::to_string(lineNo) + ": bad #include");
            out << expandIncludes(line.substr(a + 1, b - a - 1), seen);
            out << "#line " << lineNo + 1 << "\n";
        } else {
            out << line << "\n";
        }
    }
    return out.str();
}

namespace {
ShaderDefines& faultDefines() {
    static ShaderDefines d;
    return d;
}
} // namespace

void setShaderFaultDefines(ShaderDefines defines) { faultDefines() = std::move(defines); }
const ShaderDefines& shaderFaultDefines() { return faultDefines(); }
bool shaderFaultActive(const std::string& name) {
    for (const auto& d : faultDefines())
        if (d.first == name && d.second != "0") return true;
    return false;
}

int shaderFaultCount(const std::string& name) {
    for (const auto& d : faultDefines())
        if (d.first == name && !d.second.empty() && d.second.size() <= 6 && d.second.find_first_not_of("0123456789") == std::string::npos)
            return std::stoi(d.second);
    return 0;
}

std::string loadShaderSource(const std::string& relPath, const ShaderDefines& defines) {
    std::set<std::string> seen;
    std::string src = expandIncludes(relPath, seen);
    // Defines go right after the #version line, which must stay first.
    auto v = src.find("#version");
    if (v == std::string::npos) throw RuntimeError(relPath + ": missing #version");
    auto eol = src.find('\n', v);
    std::string header;
    for (const auto& [name, value] : defines) header += "#define " + name + " " + value + "\n";
    for (const auto& [name, value] : faultDefines()) header += "#define " + name + " " + value + "\n";
    header += "#line 2\n";
    return src.substr(0, eol + 1) + header + src.substr(eol + 1);
}

static GLuint compileStage(GLenum stage, const std::string& relPath, const ShaderDefines& defines) {
    std::string src = loadShaderSource(relPath, defines);
    GLuint s = glCreateShader(stage);
    const char* p = src.c_str();
    glShaderSource(s, 1, &p, nullptr);
    glCompileShader(s);
    GLint ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[8192] = {};
        glGetShaderInfoLog(s, sizeof log, nullptr, log);
        glDeleteShader(s);
        throw RuntimeError("GLSL compile error in " + relPath + ":\n" + log);
    }
    return s;
}

static GLuint link(const std::vector<GLuint>& stages, const std::string& what) {
    GLuint prog = glCreateProgram();
    for (GLuint s : stages) glAttachShader(prog, s);
    glLinkProgram(prog);
    for (GLuint s : stages) glDeleteShader(s);
    GLint ok = 0;
    glGetProgramiv(prog, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[8192] = {};
        glGetProgramInfoLog(prog, sizeof log, nullptr, log);
        glDeleteProgram(prog);
        throw RuntimeError("GLSL link error in " + what + ":\n" + log);
    }
    return prog;
}

ShaderProgram ShaderProgram::compute(const std::string& comp, const ShaderDefines& defines) {
    ShaderProgram p;
    p.program_ = GlProgramName(link({compileStage(GL_COMPUTE_SHADER, comp, defines)}, comp));
    return p;
}

ShaderProgram ShaderProgram::graphics(const std::string& vert, const std::string& frag, const ShaderDefines& defines) {
    ShaderProgram p;
    p.program_ = GlProgramName(
        link({compileStage(GL_VERTEX_SHADER, vert, defines), compileStage(GL_FRAGMENT_SHADER, frag, defines)}, vert + "+" + frag));
    return p;
}

void ShaderProgram::dispatch2D(int width, int height, int localX, int localY) const {
    use();
    glDispatchCompute(GLuint((width + localX - 1) / localX), GLuint((height + localY - 1) / localY), 1);
}

void ShaderProgram::dispatchLinear(size_t count, unsigned localSize) const {
    constexpr size_t kMaxGroups = 65535;
    const size_t groups = (count + localSize - 1) / localSize;
    const size_t gx = std::min(groups, kMaxGroups), gy = gx ? (groups + gx - 1) / gx : 0;
    set("uInvocationsPerRow", unsigned(gx * localSize));
    use();
    glDispatchCompute(GLuint(gx), GLuint(gy), 1);
}

bool hasExtension(const char* name) {
    GLint n = 0;
    glGetIntegerv(GL_NUM_EXTENSIONS, &n);
    for (GLint i = 0; i < n; ++i)
        if (std::strcmp(reinterpret_cast<const char*>(glGetStringi(GL_EXTENSIONS, GLuint(i))), name) == 0) return true;
    return false;
}

int querySubgroupSize() {
    // A ballot's uint64_t needs GL_ARB_gpu_shader_int64 to be read at all.
    if (!hasExtension("GL_ARB_shader_ballot") || !hasExtension("GL_ARB_gpu_shader_int64")) return 0;
    ShaderProgram p = ShaderProgram::compute("common/subgroup_size.comp");
    GlBuffer out(3 * sizeof(uint32_t));
    const uint32_t init[3] = {0, 0, ~0u};
    out.upload(init, sizeof init);
    out.bindBase(GL_SHADER_STORAGE_BUFFER, 0);
    p.use();
    glDispatchCompute(1, 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    auto r = out.read<uint32_t>(3);
    // The lanes a ballot holds, not gl_SubGroupSizeARB: that is only the largest size a subgroup
    // may have (ARB_shader_ballot section 7.4), and a driver may pick the width per shader. Seen
    // here: Mesa 22.3's shader cache leaves LP_NATIVE_VECTOR_WIDTH out of its key, so after one run
    // at 512 bits a cached 16-lane binary of this shader ran beside freshly compiled 8-lane ones.
    // Every shader that depends on the width checks it again itself.
    (void)r[0], (void)r[2];
    return int(r[1]);
}

} // namespace shadowlab
