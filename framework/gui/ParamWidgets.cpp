#include "framework/gui/ParamWidgets.h"

#include "framework/core/Error.h"
#include "framework/gui/Viewer.h"

#include <imgui.h>

#include <cmath>
#include <cstdlib>

namespace shadowlab {

namespace {

// SliderInt/SliderFloat only handle ranges up to half their type's range; wider ones (seeds) get a field.
constexpr double kMaxSliderSpan = 1e7;

/// Logarithmic sliders where the interesting values sit near the bottom of a wide range
/// (shadow map sizes 64–8192, biases of 1e-4 in [0, 0.01]): a display choice, not a parameter value.
ImGuiSliderFlags sliderFlags(const ParamSpec& spec) {
    if (spec.type == ParamType::Int) return spec.min > 0 && spec.max / spec.min >= 64 ? ImGuiSliderFlags_Logarithmic : 0;
    double def = std::get<double>(spec.def);
    bool wide = spec.min > 0 ? spec.max / spec.min >= 100 : (spec.min == 0 && def > 0 && def < 0.05 * spec.max);
    return (wide ? ImGuiSliderFlags_Logarithmic : 0) | ImGuiSliderFlags_AlwaysClamp;
}

std::string tooltip(const ParamSpec& spec) {
    std::string t = spec.doc + "\ndefault " + toString(spec.def);
    if (spec.type == ParamType::Int || spec.type == ParamType::Float) {
        t += ", range [" + toString(spec.type == ParamType::Int ? ParamValue(int(spec.min)) : ParamValue(spec.min)) + ", " +
             toString(spec.type == ParamType::Int ? ParamValue(int(spec.max)) : ParamValue(spec.max)) + "]";
        if (!spec.unit.empty()) t += " " + spec.unit;
    }
    t += spec.change == ParamChange::Rebuild     ? "\nchanging it rebuilds the algorithm's structures"
         : spec.change == ParamChange::Recompile ? "\nchanging it recompiles the algorithm's shaders"
                                                 : "\napplies immediately";
    return t;
}

/// The slider's display format with the unit inside it ("%d texels"), so long units never crowd the label.
std::string sliderFormat(const ParamSpec& spec, const char* number) {
    std::string unit;
    for (char c : spec.unit) unit += c == '%' ? std::string("%%") : std::string(1, c);
    return unit.empty() ? number : std::string(number) + " " + unit;
}

} // namespace

void ParamWidgets::apply(Viewer& viewer, const std::string& key, const ParamValue& value) {
    try {
        applyParamChange(viewer, key, value);
        error_.clear();
    } catch (const InputError& e) {
        error_ = e.what();
    }
}

bool ParamWidgets::drawOne(const ParamSpec& spec, ParamValue& value) {
    const char* label = spec.key.c_str();
    bool changed = false;
    ImGui::SetNextItemWidth(ImGui::GetContentRegionAvail().x * 0.62f);
    switch (spec.type) {
    case ParamType::Bool: changed = ImGui::Checkbox(label, &std::get<bool>(value)); break;
    case ParamType::Int: {
        int& v = std::get<int>(value);
        if (spec.max - spec.min > kMaxSliderSpan) changed = ImGui::InputInt(label, &v);
        else
            changed = ImGui::SliderInt(label, &v, int(spec.min), int(spec.max), sliderFormat(spec, "%d").c_str(),
                                       sliderFlags(spec));
        break;
    }
    case ParamType::Float: {
        float v = float(std::get<double>(value));
        changed = ImGui::SliderFloat(label, &v, float(spec.min), float(spec.max), sliderFormat(spec, "%.4g").c_str(),
                                     sliderFlags(spec));
        if (changed) value = double(v);
        break;
    }
    case ParamType::Enum: {
        std::string& v = std::get<std::string>(value);
        if (ImGui::BeginCombo(label, v.c_str())) {
            for (const std::string& c : spec.choices)
                if (ImGui::Selectable(c.c_str(), c == v)) { v = c; changed = true; }
            ImGui::EndCombo();
        }
        break;
    }
    }
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", tooltip(spec).c_str());
    return changed;
}

void ParamWidgets::draw(Viewer& viewer) {
    const AlgorithmChoice& choice = viewer.active();
    const ParamSchema& schema = choice.info->schema();
    if (schema.specs().empty()) ImGui::TextDisabled("(no parameters)");
    if (viewer.activeIndex() != pendingOwner_) pending_.clear(); // drags of another algorithm's sliders
    pendingOwner_ = viewer.activeIndex();
    ImGui::PushID(viewer.activeIndex());
    for (const ParamSpec& spec : schema.specs()) {
        auto it = pending_.find(spec.key);
        ParamValue value = it != pending_.end() ? it->second : choice.params.get(spec.key);
        bool changed = drawOne(spec, value);
        bool active = ImGui::IsItemActive();
        bool released = ImGui::IsItemDeactivatedAfterEdit();
        // Sliders of costly keys apply when released, not at every step of the drag.
        bool deferred = spec.change != ParamChange::Update && active &&
                        (spec.type == ParamType::Int || spec.type == ParamType::Float);
        if (deferred) {
            if (changed) pending_[spec.key] = value;
        } else if (changed || (released && it != pending_.end())) {
            pending_.erase(spec.key);
            apply(viewer, spec.key, value);
        }
    }
    ImGui::PopID();
    if (ImGui::Button("Defaults")) {
        // Only the keys that differ, in one change: at most one rebuild.
        std::vector<std::pair<std::string, ParamValue>> changes;
        for (const ParamSpec& spec : schema.specs())
            if (choice.params.get(spec.key) != spec.def) changes.emplace_back(spec.key, spec.def);
        try {
            applyParamChanges(viewer, changes);
            error_.clear();
        } catch (const InputError& e) {
            error_ = e.what();
        }
    }
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("Every parameter back to its schema default");
    if (!error_.empty()) ImGui::TextColored(ImVec4(1, 0.4f, 0.3f, 1), "%s", error_.c_str());
}

} // namespace shadowlab
