#pragma once
// The small sweep that the sweep tests run (2 × 2 runs, 64², 2 frames, a few hundred triangles,
// no warm-up, no images or plots: about a second a run on llvmpipe) and the reading of sweep.csv.
#include "framework/core/JsonNode.h"

#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace shadowlab::test {

inline Json smallSweep() {
    return Json::parse(R"({
  "name": "small",
  "base": {
    "resolution": [64, 64], "frames": 2, "warmup_frames": 0,
    "scene": {"objects": [
      {"procedural": "plane", "size": [6, 6]},
      {"procedural": "sphere", "radius": 0.5, "triangles": 300, "transform": {"translate": [0, 0.7, 0]}}
    ]},
    "camera": {"position": [0, 3, 5], "target": [0, 0, 0]},
    "light": {"position": [1, 4, 1]},
    "algorithms": [{"algorithm": "shadow_map", "params": {"resolution": 256}}, {"algorithm": "psv"}],
    "output": {"images_at_frames": [], "plots": false}
  },
  "axes": [
    {"name": "tris", "values": {"scene.objects.1.triangles": [300, 1200]}, "scale": "triangles"},
    {"name": "pcf", "values": {"algorithms.0.params.pcf": [0, 1]}}
  ],
  "merge": {"ratios": ["psv/shadow_map"]}
})");
}

inline std::string writeJson(const std::string& path, const Json& j) {
    std::ofstream(path) << j.dump(2);
    return path;
}

/// sweep.csv rows of one kind (SweepMerge.cpp: "accuracy", which depends on the config alone;
/// "counter"; "cache"; "time"), keyed "run,index,axes...,triangles,pixels,id,algorithm,measure" → value;
/// an empty kind keeps every row (with its value blanked: the keys alone).
inline std::map<std::string, std::string> rowsOfKind(const std::string& csvPath, const std::string& kind) {
    std::ifstream in(csvPath);
    std::string line;
    std::getline(in, line); // header
    std::map<std::string, std::string> rows;
    while (std::getline(in, line)) {
        const size_t valueComma = line.rfind(','), kindComma = line.rfind(',', valueComma - 1);
        if (kind.empty()) rows[line.substr(0, kindComma)] = "";
        else if (line.substr(kindComma + 1, valueComma - kindComma - 1) == kind) rows[line.substr(0, kindComma)] = line.substr(valueComma + 1);
    }
    return rows;
}

/// The run ids of sweep.csv.
inline std::set<std::string> runIds(const std::string& csvPath) {
    std::ifstream in(csvPath);
    std::string line;
    std::getline(in, line);
    std::set<std::string> ids;
    while (std::getline(in, line)) ids.insert(line.substr(0, line.find(',')));
    return ids;
}

} // namespace shadowlab::test
