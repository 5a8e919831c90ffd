// A real Slurm cluster: one node on this machine (munged, slurmctld, slurmd from a temporary
// slurm.conf, scripts/slurm_local.sh), a sweep submitted with `sweep slurm --submit`, merged, and
// compared run for run with the same sweep run locally. Needs the Debian packages munge and
// slurm-wlm (scripts/setup.sh installs them) and root; without them the test fails, it never skips.
#include "tests/SweepTestData.h"
#include "tests/TestSupport.h"

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <thread>

namespace shadowlab {
namespace {

namespace fs = std::filesystem;

std::string bin() { return SHADOWLAB_BINARY; }
/// 'text' for the shell that runCommand starts.
std::string q(const std::string& text) {
    std::string out = "'";
    for (char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
}
const std::string kScript = std::string(SHADOWLAB_SOURCE_DIR) + "/scripts/slurm_local.sh";

class SweepSlurmTest : public ::testing::Test {
protected:
    void SetUp() override {
        for (const char* tool : {"munged", "slurmctld", "slurmd", "sbatch", "squeue"}) {
            std::string out;
            ASSERT_EQ(test::runCommand(std::string("command -v ") + tool, out), 0)
                << tool << " is not installed: scripts/setup.sh installs munge and slurm-wlm";
        }
        dir_ = test::makeTempDir("slurm");
        cluster_ = dir_ + "/cluster";
        std::string out;
        started_ = true; // from here on TearDown stops whatever got started, even if start fails midway
        ASSERT_EQ(test::runCommand(kScript + " start " + cluster_, out), 0) << out;
        env_ = "SLURM_CONF=" + cluster_ + "/slurm.conf ";
    }

    void TearDown() override {
        if (!started_) return;
        // Stops exactly the three daemons this fixture started, by the pids the script recorded.
        std::string out;
        EXPECT_EQ(test::runCommand(kScript + " stop " + cluster_, out), 0) << out;
        for (const char* d : {"munged", "slurmctld", "slurmd"}) EXPECT_FALSE(fs::exists(cluster_ + "/" + d + ".pid")) << d;
    }

    /// Waits until Slurm no longer lists the job (all array tasks ended), at most `seconds`.
    bool waitForJob(const std::string& job, int seconds) {
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(seconds);
        std::string out;
        while (std::chrono::steady_clock::now() < deadline) {
            if (test::runCommand(env_ + "squeue -h -j " + job, out) == 0 && out.find_first_not_of(" \n") == std::string::npos) return true;
            std::this_thread::sleep_for(std::chrono::milliseconds(250));
        }
        return false;
    }

    std::string dir_, cluster_, env_;
    bool started_ = false;
};

TEST_F(SweepSlurmTest, ArrayJobGivesTheSameTableAsALocalRun) {
    const std::string file = test::writeJson(dir_ + "/small.sweep.json", test::smallSweep());
    // The job's folder has a space and a quote in its name: sbatch reads the quoted #SBATCH --output
    // and bash the quoted paths of the task's command as the same folder.
    const std::string local = dir_ + "/local", slurm = dir_ + "/slurm job's out";
    std::string out;
    ASSERT_EQ(test::runCommand(bin() + " sweep run " + file + " --out " + local + " --jobs 2", out), 0) << out;
    ASSERT_EQ(test::runCommand(bin() + " sweep merge " + local + " --no-plots", out), 0) << out;

    ASSERT_EQ(test::runCommand("(" + env_ + bin() + " sweep slurm " + file + " --out " + q(slurm) + " --time 00:10:00 --submit 2>/dev/null)", out), 0)
        << out;
    const std::string job = out.substr(0, out.find('\n'));
    ASSERT_FALSE(job.empty());
    ASSERT_EQ(job.find_first_not_of("0123456789"), std::string::npos) << "sbatch --parsable gives the job id: " << out;
    ASSERT_TRUE(waitForJob(job, 180)) << "job " << job << " still queued or running after 180 s";

    // One array task per run, each an ordinary `sweep run --index K` with its own log.
    std::string script;
    {
        std::ifstream in(slurm + "/sweep.sbatch");
        std::stringstream ss;
        ss << in.rdbuf();
        script = ss.str();
    }
    EXPECT_NE(script.find("#SBATCH --array=0-3"), std::string::npos) << script;
    EXPECT_NE(script.find("--index \"$SLURM_ARRAY_TASK_ID\""), std::string::npos) << script;
    for (int k = 0; k < 4; ++k) EXPECT_TRUE(fs::exists(slurm + "/slurm/" + job + "_" + std::to_string(k) + ".out")) << k;

    ASSERT_EQ(test::runCommand(bin() + " sweep merge " + q(slurm) + " --no-plots", out), 0) << out;
    EXPECT_EQ(test::runIds(slurm + "/sweep.csv").size(), 4u);
    EXPECT_EQ(test::runIds(slurm + "/sweep.csv"), test::runIds(local + "/sweep.csv"));
    // Every run, algorithm and measure on both sides, and the same accuracy. (Counters, memory and
    // overflow are compared by name only: psv's tree, built by racing GPU threads, and so its node
    // counts, differ a little from one run to the next even on one machine.)
    EXPECT_EQ(test::rowsOfKind(local + "/sweep.csv", ""), test::rowsOfKind(slurm + "/sweep.csv", ""));
    const auto a = test::rowsOfKind(local + "/sweep.csv", "accuracy"), b = test::rowsOfKind(slurm + "/sweep.csv", "accuracy");
    EXPECT_EQ(a.size(), 4u * 3u * 5u) << "4 runs × 3 algorithms × 5 accuracy measures";
    EXPECT_EQ(a, b);
}

} // namespace
} // namespace shadowlab
