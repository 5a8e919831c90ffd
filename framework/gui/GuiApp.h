#pragma once
// The application: window, Dear ImGui, the viewer and its panels, and the automation options.
#include "framework/gui/GuiOptions.h"

namespace shadowlab {

/// Runs the GUI until the window closes (or for opts.frames frames); returns the exit code.
/// Bad input (config, --algorithm, --set, ...) is an InputError thrown before any window opens.
int runGui(const GuiOptions& opts);

} // namespace shadowlab
