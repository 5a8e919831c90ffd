// The plugin: per frame four stages, `insert` (insert.comp: the lit samples into their cells),
// `jobs` (jobs.comp, job_args.comp: per triangle and face, the tiles of cells it may cover),
// `test` (test.comp: per job, the samples of each cell against the triangle, by the reference's
// ray test) and `resolve` (resolve.comp: visibility, the lost work written shadowed).
#include "algorithms/izb/Izb.h"

#include "framework/algorithm/AlgorithmSupport.h"
#include "framework/algorithm/SharedParams.h"
#include "framework/core/CheckedMath.h"
#include "framework/core/Error.h"
#include "framework/gl/GpuCounters.h"
#include "framework/render/LightUniforms.h"
#include "shaders/izb/layout.glsl"

#include <algorithm>

namespace shadowlab {
namespace {

/// The grid's side for the parameter `grid` (0 = auto) at image size r: see the schema.
int gridSide(int grid, glm::ivec2 r) { return grid > 0 ? grid : std::clamp((std::max(r.x, r.y) / 2 + 7) / 8 * 8, 64, 1024); }

enum class IzbGridFit { Scene, Samples };

struct IzbParams {
    int grid;        ///< cells per face side
    int jobCapacity; ///< jobs the list holds
    int walkCap;     ///< samples one cell's walk may test against one triangle
    bool cellTest;   ///< test each cell against the projected triangle, not only its box
    IzbGridFit gridFit;
    float rayOffset;
};

const ParamStruct<IzbParams>& izbParams() {
    using P = IzbParams;
    static const ParamStruct<P> s = ParamStruct<P>()
        // 0 = auto: half the image's longer side, a multiple of 8 in [64, 1024] (512 at 1024²: a few
        // samples per occupied cell where the light sees most of the image). At most 1024: one
        // invocation loops over a footprint's (grid / 8)^2 tiles, and llvmpipe ends an invocation's
        // loops after 65,535 iterations (docs/architecture.md, rule 13).
        .integer("grid", &P::grid, 0, 0, 1024, "cells",
                 "light-space grid, cells per side of each face (6 faces for point and spot lights, 1 directional); "
                 "0 = half the image's longer side, in [64, 1024]",
                 ParamChange::Rebuild)
        .integer("job_capacity", &P::jobCapacity, 1 << 22, 1024, 1 << 26, "jobs",
                 "(triangle, 8 × 8 tile of cells) jobs per frame; the tiles of jobs that do not fit are written shadowed and counted",
                 ParamChange::Rebuild)
        .integer("walk_cap", &P::walkCap, 16384, 16, 60000, "samples",
                 "most samples of one cell tested against one triangle; a longer list is written shadowed and counted",
                 ParamChange::Update)
        .boolean("cell_test", &P::cellTest, true,
                 "skip the cells of a triangle's box that its projection cannot touch (conservative rasterisation); off = every cell of the box",
                 ParamChange::Update)
        // scene by default: on the peer engine orbit at 512² the fitted grids spread the samples over
        // 2.5× the occupied tiles, so 2.5× the jobs, for the same tests per sample (2.6 s against
        // 1.1 s a frame); they pay where the view crowds a small part of the light's field
        // (docs/algorithms/izb.md, "Where the grid lies").
        .choice("grid_fit", &P::gridFit, IzbGridFit::Scene, {{"scene", IzbGridFit::Scene}, {"samples", IzbGridFit::Samples}},
                "where each face's grid lies: fitted every frame to the box of that face's samples (samples: the "
                "paper's reprojection of crowded regions, one fitted grid per face) or over the whole face (scene)",
                ParamChange::Recompile)
        .apply(rayOffsetRow(&P::rayOffset));
    return s;
}

const ParamSchema& izbSchema() { return izbParams().schema(); }

class Izb final : public ShadowAlgorithm {
public:
    Izb(const ParamValues& p, const AlgorithmOptions& o) : p_(izbParams().read(p)), options_(o) { compile(); }

    void setScene(const SceneGpu& scene) override {
        scene_ = &scene;
        jobs_ = GlBuffer(size_t(p_.jobCapacity) * 8, nullptr, 0);
        jobCount_ = GlBuffer(4 * sizeof(uint32_t), nullptr, GL_DYNAMIC_STORAGE_BIT);
        faceBounds_ = GlBuffer(6 * 4 * sizeof(uint32_t), nullptr, GL_DYNAMIC_STORAGE_BIT);
        counters_.allocate();
    }

    void resize(glm::ivec2 r) override {
        grid_ = gridSide(p_.grid, r);
        const size_t cells = size_t(6) * size_t(grid_) * size_t(grid_);
        const size_t tilesPerSide = size_t((grid_ + IZB_TILE - 1) / IZB_TILE);
        head_ = GlBuffer(cells * 4, nullptr, 0);
        cellFlags_ = GlBuffer(cells * 4, nullptr, 0);
        tileFlags_ = GlBuffer(6 * tilesPerSide * tilesPerSide * 4, nullptr, 0);
        occupied_ = GlBuffer(6 * tilesPerSide * tilesPerSide * 4, nullptr, 0);
        const size_t pixels = std::max<size_t>(size_t(r.x) * size_t(r.y), 1);
        next_ = GlBuffer(pixels * 4, nullptr, 0);
        samples_ = GlBuffer(pixels * 16, nullptr, 0);
        blocked_ = GlBuffer(pixels * 4, nullptr, 0);
        if (options_.statistics) listView_ = makeTexture2D(GL_R32F, r.x, r.y);
        resolution_ = r;
    }

    void paramsChanged(const ParamValues& p, ParamChange change) override {
        p_ = izbParams().read(p);
        if (change == ParamChange::Recompile) compile();
    }

    void computeVisibility(const FrameInputs& f) override {
        const bool directional = f.light.type == LightType::Directional;
        const int faces = directional ? 1 : 6;
        const unsigned triangles = unsigned(scene_->triangleCount());
        const float offset = rayOffsetLength(p_.rayOffset, *scene_);
        const glm::ivec2 r = f.gbuffer.resolution();
        counters_.clear();
        scene_->bindStorage();
        head_.bindBase(GL_SHADER_STORAGE_BUFFER, IZB_HEAD_BINDING);
        next_.bindBase(GL_SHADER_STORAGE_BUFFER, IZB_NEXT_BINDING);
        samples_.bindBase(GL_SHADER_STORAGE_BUFFER, IZB_SAMPLE_BINDING);
        blocked_.bindBase(GL_SHADER_STORAGE_BUFFER, IZB_BLOCKED_BINDING);
        jobs_.bindBase(GL_SHADER_STORAGE_BUFFER, IZB_JOB_BINDING);
        jobCount_.bindBase(GL_SHADER_STORAGE_BUFFER, IZB_JOB_COUNT_BINDING);
        tileFlags_.bindBase(GL_SHADER_STORAGE_BUFFER, IZB_FLAG_BINDING);
        cellFlags_.bindBase(GL_SHADER_STORAGE_BUFFER, IZB_CELL_FLAG_BINDING);
        occupied_.bindBase(GL_SHADER_STORAGE_BUFFER, IZB_OCCUPIED_BINDING);
        faceBounds_.bindBase(GL_SHADER_STORAGE_BUFFER, IZB_BOUNDS_BINDING);
        counters_.bindBase(GL_SHADER_STORAGE_BUFFER, IZB_COUNTER_BINDING);
        for (const ShaderProgram* program : {&bounds_, &insert_, &jobsPass_, &test_, &resolve_}) {
            setLightUniforms(*program, f.light);
            setGrid(*program, f.light);
        }

        f.timer.begin("insert");
        head_.clearUint(IZB_NONE);
        cellFlags_.clearUint(0);
        tileFlags_.clearUint(0);
        occupied_.clearUint(0);
        jobCount_.clearUint(0);
        bindPixelPassInputs(f);
        if (p_.gridFit == IzbGridFit::Samples) {
            // Empty boxes: min words at the top of the order, max words at the bottom.
            uint32_t empty[24];
            for (int face = 0; face < 6; ++face)
                for (int k = 0; k < 4; ++k) empty[4 * face + k] = k < 2 ? 0xFFFFFFFFu : 0u;
            faceBounds_.upload(empty, sizeof(empty));
            bounds_.set("uResolution", r);
            bounds_.set("uRayOffset", offset);
            bounds_.dispatch2D(r.x, r.y, 8, 8);
            glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        }
        insert_.set("uResolution", r);
        insert_.set("uRayOffset", offset);
        insert_.dispatch2D(r.x, r.y, 8, 8);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        f.timer.end();

        f.timer.begin("jobs");
        jobsPass_.set("uTriangleCount", triangles);
        jobsPass_.set("uFaces", faces);
        jobsPass_.set("uJobCapacity", unsigned(p_.jobCapacity));
        jobsPass_.dispatchLinear(std::max<size_t>(1, size_t(triangles) * size_t(faces)), 64);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        jobArgs_.set("uJobCapacity", unsigned(p_.jobCapacity));
        jobArgs_.use();
        glDispatchCompute(1, 1, 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_COMMAND_BARRIER_BIT);
        f.timer.end();

        f.timer.begin("test");
        test_.set("uRayOffset", offset);
        test_.set("uWalkCap", unsigned(p_.walkCap));
        test_.set("uCellTest", p_.cellTest ? 1 : 0);
        test_.use();
        glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, jobCount_.id());
        glDispatchComputeIndirect(sizeof(uint32_t));
        glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, 0);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        f.timer.end();

        f.timer.begin("resolve");
        resolve_.set("uResolution", r);
        if (options_.statistics) runPixelPass(f, resolve_, {&listView_});
        else runPixelPass(f, resolve_, {});
        f.timer.end();
        counters_.markStale();
        faces_ = faces;
    }

    std::vector<Counter> counters() const override {
        const auto& c = counters_.read();
        std::vector<Counter> out = {{"samples", double(c[IZB_C_SAMPLES])},
                                    {"jobs", double(c[IZB_C_JOBS])},
                                    {"lost_tiles", double(c[IZB_C_LOST_TILES])},
                                    {"capped_cells", double(c[IZB_C_CAPPED_CELLS])},
                                    {"loop_capped_pixels", double(c[IZB_C_CUT_LOOPS])},
                                    {"overflow_pixels", double(c[IZB_C_OVERFLOW_PIXELS])},
                                    {"grid_faces", double(faces_)}};
        if (options_.statistics) {
            const double samples = double(c[IZB_C_SAMPLES]);
            out.push_back({"tests_per_sample", samples > 0 ? double(counters_.wide(IZB_C_TESTS_LO)) / samples : 0.0});
            out.push_back({"list_max", double(c[IZB_C_LIST_MAX])});
        }
        return out;
    }
    std::vector<DebugView> debugViews() const override {
        if (!options_.statistics) return {};
        return {{"list_length", listView_.id(), 0.0f, "samples in the pixel's cell"}};
    }
    size_t memoryBytes() const override {
        return head_.size() + cellFlags_.size() + tileFlags_.size() + occupied_.size() + jobs_.size() + jobCount_.size() + next_.size() +
               samples_.size() + blocked_.size() + counters_.size();
    }
    std::vector<std::pair<std::string, std::string>> resolvedParams() const override {
        return {{"grid", std::to_string(grid_)}};
    }
    uint64_t overflowCount() const override {
        const auto& c = counters_.read();
        return uint64_t(c[IZB_C_OVERFLOW_PIXELS]);
    }

private:
    /// The grid's uniforms (grid.glsl): a directional light's square across its direction, around
    /// the scene's bounding sphere (widened so every ray origin, offset off a surface, falls in).
    void setGrid(const ShaderProgram& program, const Light& light) const {
        program.set("uGrid", grid_);
        const Bounds& b = scene_->bounds();
        const glm::vec3 c = b.empty() ? glm::vec3(0.0f) : b.center();
        const float radius = (b.empty() ? 1.0f : std::max(b.radius(), 1e-6f)) * 1.01f;
        const glm::vec3 d = light.direction();
        const glm::vec3 helper = std::abs(d.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
        const glm::vec3 u = glm::normalize(glm::cross(d, helper)), v = glm::cross(d, u);
        program.set("uGridCenter", c);
        program.set("uGridRadius", radius);
        program.set("uGridU", u);
        program.set("uGridV", v);
    }

    void compile() {
        const auto instr = statisticsDefine(options_);
        const std::pair<std::string, std::string> texels{"SCENE_POSITION_TEXELS", "1"};
        const std::pair<std::string, std::string> fit{"IZB_FIT_SAMPLES", p_.gridFit == IzbGridFit::Samples ? "1" : "0"};
        bounds_ = ShaderProgram::compute("izb/bounds.comp", {});
        insert_ = ShaderProgram::compute("izb/insert.comp", {fit});
        jobsPass_ = ShaderProgram::compute("izb/jobs.comp", {texels, fit});
        jobArgs_ = ShaderProgram::compute("izb/job_args.comp", {});
        test_ = ShaderProgram::compute("izb/test.comp", {instr, texels, fit});
        resolve_ = ShaderProgram::compute("izb/resolve.comp", {instr, fit});
    }

    IzbParams p_;
    AlgorithmOptions options_;
    const SceneGpu* scene_ = nullptr;
    glm::ivec2 resolution_{0};
    int faces_ = 6;
    int grid_ = 64; ///< `grid` as resolved for the image size
    ShaderProgram bounds_, insert_, jobsPass_, jobArgs_, test_, resolve_;
    GlBuffer head_, next_, samples_, blocked_, jobs_, jobCount_, tileFlags_, cellFlags_, occupied_, faceBounds_;
    GlTexture listView_;
    GpuCounters<IZB_COUNTER_WORDS> counters_;
};

} // namespace

/// Per pixel (lists, samples, visibility) and per cell of its grid; the triangles are read through
/// the scene positions' view.
Footprint izbFootprint(const FootprintQuery& q) {
    // The buffers resize() and the constructor make, at the configured grid and job capacity.
    const size_t grid = size_t(gridSide(std::get<int>(q.params->get("grid")), q.resolution));
    const size_t cells = 6 * grid * grid, tiles = 6 * ((grid + IZB_TILE - 1) / IZB_TILE) * ((grid + IZB_TILE - 1) / IZB_TILE);
    const size_t pixels = size_t(q.resolution.x) * size_t(q.resolution.y);
    const size_t jobs = size_t(std::get<int>(q.params->get("job_capacity"))) * 8;
    Footprint f;
    f.bytes = saturatingSum({saturatingMul(pixels, 24 + 32), jobs, cells * 8, tiles * 8, 4096});
    f.refusal = texelRefusal(q, "the scene positions' view it reads", saturatingMul(3, q.triangles));
    return f;
}
AlgorithmInfo izbInfo() {
    AlgorithmInfo info = makeAlgorithmInfo<Izb>("izb", "irregular z-buffer: view samples in a light-space grid, triangles rasterised conservatively onto it and tested exactly",
                                  {LightType::Point, LightType::Spot, LightType::Directional}, true, &izbSchema);
    info.footprint = &izbFootprint;
    return info;
}

} // namespace shadowlab
