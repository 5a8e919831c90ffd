#pragma once
// Parameter widgets generated from an algorithm's ParamSchema: bool → checkbox, int/float → slider
// over the schema's range (unit beside it, doc as tooltip), enum → combo. No parameter name, range
// or default is written here; every change goes through applyParamChanges().
#include "framework/core/Params.h"

#include <map>
#include <string>

namespace shadowlab {

class Viewer;

class ParamWidgets {
public:
    /// Draws one widget per parameter of the active algorithm and applies the edits.
    void draw(Viewer& viewer);
    /// The last rejected edit ("" when the last one applied).
    const std::string& error() const { return error_; }

private:
    void apply(Viewer& viewer, const std::string& key, const ParamValue& value);
    bool drawOne(const ParamSpec& spec, ParamValue& value);

    // Rebuild parameters are applied when the slider is released, not on every drag step (each
    // step would rebuild maps or trees); until then the dragged value lives here.
    std::map<std::string, ParamValue> pending_;
    int pendingOwner_ = -1;
    std::string error_;
};

} // namespace shadowlab
