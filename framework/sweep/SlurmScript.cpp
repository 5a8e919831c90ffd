#include "framework/sweep/SlurmScript.h"

#include "framework/core/Error.h"
#include "framework/experiment/Results.h"
#include "framework/sweep/SweepRunner.h"

#include <array>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <sys/wait.h>

namespace shadowlab {

namespace fs = std::filesystem;

namespace {

/// 'text' for bash, single quotes escaped.
std::string quote(const std::string& text) {
    std::string out = "'";
    for (char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
}

} // namespace

std::string slurmScript(const Sweep& sweep, const SlurmOptions& o, const std::string& binary) {
    const std::string dir = fs::absolute(o.outputDir).lexically_normal().string();
    const size_t runs = sweep.runs.size(), tasks = o.shards ? std::min(o.shards, runs) : runs;
    std::ostringstream s;
    s << "#!/bin/bash\n"
      << "# Sweep \"" << sweep.name << "\" (" << runs << " runs) from " << fs::absolute(sweep.file).string() << ", written by\n"
      << "# `shadowlab sweep slurm`. Each array task runs " << (o.shards ? "one shard of the runs" : "one run")
      << " with `shadowlab sweep run`, which skips\n"
      << "# complete runs: submitting this script again finishes a sweep that was cut short.\n"
      << "#SBATCH --job-name=" << quote("shadowlab-" + sweep.name) << "\n"
      << "#SBATCH --array=0-" << (tasks ? tasks - 1 : 0) << (o.maxParallel ? "%" + std::to_string(o.maxParallel) : "") << "\n"
      << "#SBATCH --ntasks=1\n"
      << "#SBATCH --output=" << dir << "/slurm/%A_%a.out\n";
    if (!o.partition.empty()) s << "#SBATCH --partition=" << o.partition << "\n";
    if (o.gpusPerTask > 0) s << "#SBATCH --gpus-per-task=" << o.gpusPerTask << "\n";
    if (o.cpusPerTask > 0) s << "#SBATCH --cpus-per-task=" << o.cpusPerTask << "\n";
    if (!o.time.empty()) s << "#SBATCH --time=" << o.time << "\n";
    s << "set -euo pipefail\n"
      << "exec " << quote(binary) << " sweep run " << quote(dir + "/sweep.json") << " --out " << quote(dir) << " "
      << (o.shards ? "--shard \"$SLURM_ARRAY_TASK_ID/" + std::to_string(tasks) + "\"" : std::string("--index \"$SLURM_ARRAY_TASK_ID\""))
      << "\n";
    return s.str();
}

std::string writeSlurmScript(const Sweep& sweep, const SlurmOptions& o, const std::string& binary) {
    std::string runner = binary;
    if (o.gpusPerTask > 0) {
        // GPU nodes have no display: the EGL runner (surfaceless) drives the GPU there.
        runner = (fs::path(binary).parent_path() / "shadowlab-egl").string();
        if (!fs::exists(runner))
            throw InputError("--gpus-per-task", "", runner + " does not exist (build it with the EGL development files installed)");
    }
    writeSweepSnapshot(sweep, o.outputDir);
    fs::create_directories(o.outputDir + "/slurm");
    const std::string path = o.outputDir + "/sweep.sbatch";
    writeFileAtomic(path, slurmScript(sweep, o, runner));
    fs::permissions(path, fs::perms::owner_exec, fs::perm_options::add);
    return path;
}

std::string submitSlurmScript(const std::string& script) {
    FILE* p = popen(("sbatch --parsable " + quote(script) + " 2>&1").c_str(), "r");
    if (!p) throw RuntimeError("cannot run sbatch");
    std::string out;
    std::array<char, 512> buf;
    size_t n;
    while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) out.append(buf.data(), n);
    const int status = pclose(p);
    while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
        throw RuntimeError("sbatch " + script + " failed" + (WIFEXITED(status) && WEXITSTATUS(status) == 127 ? " (is Slurm installed?)" : "") +
                           ": " + out);
    // --parsable prints "JOBID" or "JOBID;CLUSTER" (possibly after warnings on earlier lines).
    std::string last = out.substr(out.find_last_of('\n') == std::string::npos ? 0 : out.find_last_of('\n') + 1);
    return last.substr(0, last.find(';'));
}

} // namespace shadowlab
