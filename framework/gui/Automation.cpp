#include "framework/gui/Automation.h"

#include "framework/core/Error.h"
#include "framework/experiment/Results.h"
#include "framework/gl/GlContext.h"
#include "framework/gui/GuiState.h"

namespace shadowlab {

namespace {

Json vec(glm::vec3 v) { return Json::array({v.x, v.y, v.z}); }

std::string joined(const std::vector<std::string>& items) {
    std::string s;
    for (const auto& i : items) s += (s.empty() ? "" : ", ") + i;
    return s;
}

} // namespace

AutomationPlan planAutomation(const GuiOptions& opts, const ExperimentConfig& config) {
    AutomationPlan plan;
    std::vector<AlgorithmChoice> choices = algorithmChoices(config);
    if (!opts.algorithm.empty()) {
        plan.choice = findChoice(choices, opts.algorithm);
        if (plan.choice < 0) {
            std::vector<std::string> labels;
            for (const auto& c : choices) labels.push_back(c.label + (c.fromConfig ? " (config)" : ""));
            throw InputError("--algorithm", "", "unknown algorithm \"" + opts.algorithm + "\"; choices: " + joined(labels));
        }
    }
    const AlgorithmChoice& choice = choices[size_t(plan.choice)];
    ParamValues trial = choice.params;
    for (const auto& [key, text] : opts.sets) {
        const ParamSpec* spec = choice.info->schema().find(key);
        if (!spec) {
            std::vector<std::string> keys;
            for (const auto& sp : choice.info->schema().specs()) keys.push_back(sp.key);
            throw InputError("--set", key, "unknown parameter of " + choice.info->name + "; accepted: " + joined(keys));
        }
        try {
            // Read like shadowlab's --set (JSON, else a string) and checked like a config, on a copy.
            trial.setJson(key, parseJsonOrString(text));
        } catch (const InputError& e) {
            throw InputError("--set", key, e.cause());
        }
        plan.sets.push_back({key, trial.get(key)});
    }
    // Rules between parameters, once every --set is in (their order does not matter).
    std::string why;
    if (const ParamRule* r = trial.brokenRule(&why)) throw InputError("--set", r->key, why);
    plan.params = trial;
    if (opts.startFrame >= config.frames)
        throw InputError("--frame", "", "frame " + std::to_string(opts.startFrame) + " is outside [0, " +
                                            std::to_string(config.frames - 1) + "]");
    return plan;
}

ExperimentConfig configAsStarted(const ExperimentConfig& config, const AutomationPlan& plan) {
    ExperimentConfig started = config;
    const std::vector<AlgorithmChoice> choices = algorithmChoices(config);
    const AlgorithmChoice& choice = choices[size_t(plan.choice)];
    const ParamValues& params = plan.params ? *plan.params : choice.params;
    if (!choice.fromConfig) {
        started.algorithms.push_back({choice.label, choice.info, params, "--algorithm"});
        return started;
    }
    for (AlgorithmEntry& e : started.algorithms)
        if (e.id == choice.label) e.params = params;
    if (started.reference && started.referenceEntry.id == choice.label) started.referenceEntry.params = params;
    return started;
}

void applyAutomation(GuiState& s, const GuiOptions& opts, const AutomationPlan& plan) {
    Viewer& v = *s.viewer;
    v.selectAlgorithm(plan.choice);
    applyParamChanges(v, plan.sets); // one rebuild at most, whatever the number of --set

    if (opts.view == "visibility") s.views.mode = ViewMode::Visibility;
    if (opts.view == "heat") s.views.mode = ViewMode::Heat;
    if (opts.view == "difference") s.views.mode = ViewMode::Difference;
    v.playback.frame = opts.startFrame;

    if (!opts.recordKeyframes.empty()) {
        if (opts.recordStep > 0) s.recorder.step = opts.recordStep;
        for (const auto& [position, target] : opts.recordKeyframes) {
            v.camera.position = position;
            v.camera.target = target;
            s.recorder.addKeyframe(v.camera); // what the Add keyframe button does
        }
        if (!opts.saveConfig.empty() && !saveRecording(s, opts.saveConfig)) throw InputError("--save-config", "", s.message);
        useRecording(s);
    }
    v.playback.playing = opts.play;
}

void FrameReport::add(const Viewer& v) {
    Json stages = Json::object();
    for (const StageTime& st : v.lastStages()) stages[st.name] = {{"gpu_ms", st.gpuMs}, {"cpu_ms", st.cpuMs}};
    const double gpu = sumGpuMs(v.lastStages());
    frames_.push_back({{"path_frame", v.playback.frame},
                       {"scene_time", v.sceneTime()},
                       {"camera", {{"position", vec(v.camera.position)}, {"target", vec(v.camera.target)}}},
                       {"light", {{"position", vec(v.light.position)}, {"target", vec(v.light.target)}}},
                       {"resolution", {v.resolution().x, v.resolution().y}},
                       {"algorithm", v.active().label},
                       {"gpu_ms", gpu},
                       {"stages", stages}});
}

void FrameReport::write(const std::string& file, const GuiState& s) const {
    const Viewer& v = *s.viewer;
    Json out = {{"renderer", glRendererString()},
                {"gl_version", glVersionString()},
                {"config", v.config().file},
                {"algorithm", v.active().label},
                {"algorithm_name", v.active().info->name},
                {"params", v.active().params.toJson()},
                {"recorded_keyframes", s.recorder.path().toJson()},
                {"message", s.message},
                {"frames", frames_}};
    writeFileAtomic(file, out.dump(2) + "\n");
}

} // namespace shadowlab
