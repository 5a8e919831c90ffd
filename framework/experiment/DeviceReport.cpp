#include "framework/experiment/DeviceReport.h"

#include "framework/algorithm/AlgorithmHost.h"
#include "framework/gl/DeviceInfo.h"
#include "framework/scene/Procedural.h"

#include <glm/gtc/matrix_transform.hpp>

#include <cstdio>
#include <sstream>

namespace shadowlab {

std::vector<ResolvedDefaults> resolveDefaults() {
    // A ground plane and a sphere above it (about a hundred triangles): every algorithm accepts
    // it, and none spends noticeable time preprocessing it.
    Scene scene = makePlane({4.0f, 4.0f}, 2, Material{});
    scene.append(makeSphere(0.5f, 104, Material{}), glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, 1.0f, 0.0f)));
    scene.updateBounds();
    SceneGpu sceneGpu(scene);
    std::vector<ResolvedDefaults> out;
    for (const AlgorithmInfo& info : algorithmRegistry()) {
        ResolvedDefaults r{info.name, {}, {}};
        try {
            ParamValues params(info.schema());
            if (const ParamSpec* cache = info.schema().find("cache"); cache && cache->type == ParamType::Bool)
                params.set("cache", false);
            AlgorithmHost host(info, params, AlgorithmOptions{false});
            host.resize({16, 16});
            host.setScene(sceneGpu);
            r.params = host.algorithm().resolvedParams();
        } catch (const std::exception& e) {
            r.error = e.what();
        }
        out.push_back(std::move(r));
    }
    return out;
}

Json deviceInfoJson(const Json& device, const std::vector<ResolvedDefaults>& algorithms) {
    Json algs = Json::object();
    for (const ResolvedDefaults& a : algorithms) {
        if (!a.error.empty()) {
            algs[a.algorithm] = {{"error", a.error}};
            continue;
        }
        Json resolved = Json::object();
        for (const auto& [k, v] : a.params) resolved[k] = v;
        algs[a.algorithm] = {{"resolved_params", resolved}};
    }
    return {{"device", device}, {"algorithms", algs}};
}

namespace {

std::string limitText(const std::string& name, const Json& v) {
    if (v.is_array()) {
        std::string s;
        for (size_t i = 0; i < v.size(); ++i) s += (i ? " × " : "") + std::to_string(v[i].get<long long>());
        return s;
    }
    const long long n = v.get<long long>();
    std::string s = std::to_string(n);
    if (isByteLimit(name)) s += n >= (1ll << 20) ? " (" + std::to_string(n >> 20) + " MiB)" : " (" + std::to_string(n >> 10) + " KiB)";
    return s;
}

} // namespace

std::string deviceInfoText(const Json& d, const std::vector<ResolvedDefaults>& algorithms) {
    std::ostringstream os;
    const int subgroup = d.at("subgroup_size").get<int>();
    os << "GL implementation\n"
       << "  vendor         " << d.at("vendor").get<std::string>() << "\n"
       << "  renderer       " << d.at("renderer").get<std::string>() << "\n"
       << "  version        " << d.at("version").get<std::string>() << "\n"
       << "  GLSL           " << d.at("glsl_version").get<std::string>() << "\n"
       << "  back end       " << d.at("backend").get<std::string>() << "\n"
       << "  subgroup width " << subgroup << (subgroup == 0 ? " (no ARB_shader_ballot)" : "") << "\n";
    os << "limits\n";
    for (const auto& [name, v] : d.at("limits").items()) {
        char line[160];
        std::snprintf(line, sizeof line, "  %-40s %s\n", name.c_str(), limitText(name, v).c_str());
        os << line;
    }
    os << "extensions (used by the shaders named, or by the host)\n";
    const Json& present = d.at("extensions");
    const std::vector<ExtensionUse> uses = shaderExtensions();
    for (const auto& [name, has] : present.items()) {
        std::string files;
        for (const ExtensionUse& u : uses)
            if (u.name == name)
                for (const auto& f : u.files) files += (files.empty() ? "" : ", ") + f;
        char line[400];
        std::snprintf(line, sizeof line, "  %-28s %-7s %s\n", name.c_str(), has.get<bool>() ? "yes" : "MISSING",
                      files.empty() ? "(host)" : files.c_str());
        os << line;
    }
    os << "algorithms (device-dependent parameters with the defaults)\n";
    for (const ResolvedDefaults& a : algorithms) {
        char name[40];
        std::snprintf(name, sizeof name, "  %-14s ", a.algorithm.c_str());
        os << name;
        if (!a.error.empty()) {
            os << "cannot be created here: " << a.error.substr(0, a.error.find('\n')) << "\n";
            continue;
        }
        if (a.params.empty()) os << "-";
        for (size_t i = 0; i < a.params.size(); ++i) os << (i ? ", " : "") << a.params[i].first << " = " << a.params[i].second;
        os << "\n";
    }
    return os.str();
}

} // namespace shadowlab
