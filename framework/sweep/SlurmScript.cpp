#include "framework/sweep/SlurmScript.h"

#include "framework/core/Error.h"
#include "framework/core/FileIO.h"
#include "framework/sweep/SweepProcess.h"
#include "framework/sweep/SweepRunner.h"
#include "framework/sweep/SweepText.h"

#include <cctype>
#include <filesystem>
#include <regex>
#include <sstream>

namespace shadowlab {

namespace fs = std::filesystem;

namespace {

/// 'text' with each ' written as '\'': one word for bash, and for sbatch's reading of #SBATCH lines
/// too (quotes group, a backslash escapes the next character, an unquoted # starts a comment).
std::string quote(const std::string& text) {
    std::string out = "'";
    for (char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
}

bool isSlurmNameChar(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.' || c == '-'; }

/// The job name: Slurm shows it in squeue's narrow columns; anything but a name character becomes '_'.
std::string jobName(const std::string& sweepName) {
    std::string out = "shadowlab-";
    for (char c : sweepName.substr(0, 100)) out += isSlurmNameChar(c) ? c : '_';
    return out;
}

} // namespace

void checkSlurmOptions(const SlurmOptions& o) {
    if (!o.partition.empty()) {
        static const std::regex partition("[A-Za-z0-9_.-]+(,[A-Za-z0-9_.-]+)*");
        if (o.partition.size() > 200 || !std::regex_match(o.partition, partition))
            throw InputError("--partition", "", "\"" + shortText(o.partition, 60) +
                                                    "\" is not a Slurm partition name (letters, digits, _ . -; several separated by commas)");
    }
    if (!o.time.empty()) {
        // sbatch(1): "minutes", "minutes:seconds", "hours:minutes:seconds", "days-hours",
        // "days-hours:minutes", "days-hours:minutes:seconds"; and no limit at all.
        static const std::regex time("[0-9]{1,9}(:[0-9]{1,2}){0,2}|[0-9]{1,5}-[0-9]{1,2}(:[0-9]{1,2}){0,2}|UNLIMITED|unlimited|INFINITE|infinite");
        if (!std::regex_match(o.time, time))
            throw InputError("--time", "", "\"" + shortText(o.time, 60) +
                                               "\" is not a Slurm time limit (M, M:S, H:M:S, D-H, D-H:M, D-H:M:S, or UNLIMITED)");
    }
    if (o.gpusPerTask < 0 || o.gpusPerTask > 64) throw InputError("--gpus-per-task", "", "expected 0 to 64");
    if (o.cpusPerTask < 0 || o.cpusPerTask > 1024) throw InputError("--cpus-per-task", "", "expected 0 to 1024");
    const std::string dir = absoluteFolder(o.outputDir);
    if (const std::string why = pathTextProblem(dir); !why.empty())
        throw InputError(o.outputFrom, o.outputJsonPath, "the folder's path " + why);
    if (dir.find_first_of("%\\") != std::string::npos)
        throw InputError(o.outputFrom, o.outputJsonPath,
                         "\"" + shortText(dir, 200) + "\" holds % or \\, which sbatch's --output reads as a file name pattern");
}

std::string slurmScript(const Sweep& sweep, const SlurmOptions& o, const std::string& binary) {
    checkSlurmOptions(o);
    const std::string dir = absoluteFolder(o.outputDir);
    const size_t runs = sweep.runs.size(), tasks = o.shards ? std::min(o.shards, runs) : runs;
    std::ostringstream s;
    // Comments too hold only printable text: a newline there would start a line of its own.
    s << "#!/bin/bash\n"
      << "# Sweep \"" << shortText(sweep.name) << "\" (" << runs << " runs) from " << shortText(fs::absolute(sweep.file).string(), 300)
      << ", written by\n"
      << "# `shadowlab sweep slurm`. Each array task runs " << (o.shards ? "one shard of the runs" : "one run")
      << " with `shadowlab sweep run`, which skips\n"
      << "# complete runs: submitting this script again finishes a sweep that was cut short.\n"
      << "#SBATCH --job-name=" << quote(jobName(sweep.name)) << "\n"
      << "#SBATCH --array=0-" << (tasks ? tasks - 1 : 0) << (o.maxParallel ? "%" + std::to_string(o.maxParallel) : "") << "\n"
      << "#SBATCH --ntasks=1\n"
      << "#SBATCH --output=" << quote(dir + "/slurm/%A_%a.out") << "\n";
    if (!o.partition.empty()) s << "#SBATCH --partition=" << quote(o.partition) << "\n";
    if (o.gpusPerTask > 0) s << "#SBATCH --gpus-per-task=" << o.gpusPerTask << "\n";
    if (o.cpusPerTask > 0) s << "#SBATCH --cpus-per-task=" << o.cpusPerTask << "\n";
    if (!o.time.empty()) s << "#SBATCH --time=" << quote(o.time) << "\n";
    s << "set -euo pipefail\n"
      << "exec " << quote(binary) << " sweep run " << quote(dir + "/sweep.json") << " --out " << quote(dir) << " "
      << (o.shards ? "--shard \"$SLURM_ARRAY_TASK_ID/" + std::to_string(tasks) + "\"" : std::string("--index \"$SLURM_ARRAY_TASK_ID\""))
      << "\n";
    return s.str();
}

std::string writeSlurmScript(const Sweep& sweep, const SlurmOptions& o, const std::string& binary) {
    checkSlurmOptions(o); // before anything is written
    std::string runner = binary;
    if (o.gpusPerTask > 0) {
        // GPU nodes have no display: the EGL runner (surfaceless) drives the GPU there.
        runner = (fs::path(binary).parent_path() / "shadowlab-egl").string();
        if (!fs::exists(runner))
            throw InputError("--gpus-per-task", "", runner + " does not exist (build it with the EGL development files installed)");
    }
    writeSweepSnapshot(sweep, o.outputDir);
    const std::string dir = absoluteFolder(o.outputDir);
    std::error_code ec;
    if (fs::exists(fs::symlink_status(dir + "/slurm", ec)) && !fs::is_directory(dir + "/slurm"))
        throw InputError(shortText(dir + "/slurm", 300), "", "is not a folder (the tasks' logs go there)");
    fs::create_directories(dir + "/slurm");
    // Absolute: sbatch must never take the script's path for an option.
    const std::string path = dir + "/sweep.sbatch";
    writeFileAtomic(path, slurmScript(sweep, o, runner));
    fs::permissions(path, fs::perms::owner_exec, fs::perm_options::add);
    return path;
}

std::string submitSlurmScript(const std::string& script) {
    std::string out;
    const int rc = captureChild({"sbatch", "--parsable", script}, out);
    while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
    if (rc != 0)
        throw RuntimeError("sbatch " + shortText(script, 300) + " failed" + (rc == 127 ? " (is Slurm installed?)" : "") + ": " +
                           shortText(out, 500));
    // --parsable prints "JOBID" or "JOBID;CLUSTER" (possibly after warnings on earlier lines).
    const size_t nl = out.find_last_of('\n');
    const std::string last = out.substr(nl == std::string::npos ? 0 : nl + 1), job = last.substr(0, last.find(';'));
    if (job.empty() || job.find_first_not_of("0123456789") != std::string::npos)
        throw RuntimeError("sbatch " + shortText(script, 300) + " printed no job id: " + shortText(out, 500));
    return job;
}

} // namespace shadowlab
