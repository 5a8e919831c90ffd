// What a reader of an experiment sees: heat maps on a robust scale with their legend beside them,
// a labelled contact sheet per frame with images, report.md showing every figure, and report.html
// holding them all (checked in a real headless browser: every image decodes).
#include "framework/core/JsonNode.h"
#include "framework/metrics/Images.h"
#include "tests/TestSupport.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

namespace shadowlab {
namespace {

namespace fs = std::filesystem;

std::string slurp(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

size_t count(const std::string& text, const std::string& what) {
    size_t n = 0;
    for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + what.size())) ++n;
    return n;
}

/// Width and height from a PNG's IHDR chunk; {0, 0} if the bytes are no PNG.
std::pair<int, int> pngSize(const std::string& bytes) {
    if (bytes.size() < 24 || bytes.compare(0, 8, "\x89PNG\r\n\x1a\n") != 0) return {0, 0};
    auto be = [&](size_t at) {
        return int((unsigned char)bytes[at]) << 24 | int((unsigned char)bytes[at + 1]) << 16 |
               int((unsigned char)bytes[at + 2]) << 8 | int((unsigned char)bytes[at + 3]);
    };
    return {be(16), be(20)};
}

std::string base64Decode(const std::string& in) {
    static const std::string abc = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    int bits = 0, acc = 0;
    for (char c : in) {
        size_t v = abc.find(c);
        if (v == std::string::npos) break;  // '=' padding ends the data
        acc = acc << 6 | int(v);
        if ((bits += 6) >= 8) out.push_back(char((acc >> (bits -= 8)) & 0xff));
    }
    return out;
}

TEST(HeatScaleTest, AFewHotPixelsDoNotDarkenTheMap) {
    // 1000 pixels at 10 and 5 at 1000: the data maximum would draw the 1000 at a 1 % of the ramp.
    std::vector<float> values(200, 0.0f);
    values.insert(values.end(), 1000, 10.0f);
    values.insert(values.end(), 5, 1000.0f);
    HeatScale s = heatMapScale(values, 0.0f);
    EXPECT_EQ(s.kind, HeatScale::Kind::P99);
    EXPECT_STREQ(heatScaleName(s.kind), "p99");
    EXPECT_EQ(s.min, 0.0f);
    EXPECT_EQ(s.max, 10.0f);
    EXPECT_EQ(s.dataMax, 1000.0f);
    EXPECT_EQ(s.nonZero, 1005u);
    EXPECT_EQ(s.clipped, 5u);
    // The common value takes the ramp's top colour, as do the clipped ones; zero its bottom.
    auto rgba = heatMapImage(values, s);
    const auto& top = heatRampStops().back();
    const auto& bottom = heatRampStops().front();
    for (size_t i : {size_t(500), values.size() - 1})
        for (int c = 0; c < 3; ++c) EXPECT_EQ(rgba[4 * i + c], (unsigned char)std::lround(top[c] * 255.0f)) << i;
    for (int c = 0; c < 3; ++c) EXPECT_EQ(rgba[c], (unsigned char)std::lround(bottom[c] * 255.0f));
}

TEST(HeatScaleTest, AViewsFixedMaximumIsKept) {
    std::vector<float> flags = {0, 0, 1, 0, 3};
    HeatScale s = heatMapScale(flags, 1.0f);
    EXPECT_EQ(s.kind, HeatScale::Kind::Fixed);
    EXPECT_EQ(s.max, 1.0f);
    EXPECT_EQ(s.dataMax, 3.0f);
    EXPECT_EQ(s.clipped, 1u);
    // An all-zero map still has a usable range, and the old entry point reports the scale used.
    float used = 0;
    heatMapImage(std::vector<float>(4, 0.0f), 0.0f, &used);
    EXPECT_EQ(used, 1.0f);
    EXPECT_EQ(heatMapScale(std::vector<float>(4, 0.0f), 0.0f).clipped, 0u);
}

/// One small experiment for every test below: a shadow map, psv and metric_tree (heat maps with a
/// fixed and a p99 scale), images on frame 1 of 2, at a non-square resolution.
class ReportTest : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        dir_ = test::makeTempDir("report") + "/out";
        const std::string config = test::makeTempDir("report-config") + "/report.json";
        Json c = Json::parse(slurp(std::string(SHADOWLAB_SOURCE_DIR) + "/configs/smoke.json"));
        c["name"] = "report";
        c["resolution"] = Json::array({64, 48});
        c["frames"] = 2;
        Json chosen = Json::array();
        for (const Json& a : c["algorithms"])
            if (a["algorithm"] == "shadow_map" || a["algorithm"] == "psv" || a["algorithm"] == "metric_tree") chosen.push_back(a);
        c["algorithms"] = chosen;
        c.erase("expect");  // they name ids left out here
        c["output"] = {{"images_at_frames", {1}}};
        std::ofstream(config) << c.dump(2);
        runStatus_ = test::runCommand(std::string(SHADOWLAB_BINARY) + " run " + config + " --no-progress --out " + dir_, runLog_);
    }
    void SetUp() override {
        ASSERT_EQ(runStatus_, 0) << runLog_;
        ASSERT_FALSE(fs::exists(dir_ + "/plots.log")) << slurp(dir_ + "/plots.log");
    }
    static inline std::string dir_, runLog_;
    static inline int runStatus_ = -1;
};

TEST_F(ReportTest, EveryHeatMapHasItsLegendAndALabelledCopy) {
    std::set<std::string> views;
    for (const auto& e : fs::directory_iterator(dir_ + "/images")) {
        const std::string name = e.path().filename().string();
        if (name.find("_heat_") == std::string::npos || !name.ends_with(".png") || name.ends_with("_labelled.png")) continue;
        const std::string stem = e.path().string().substr(0, e.path().string().size() - 4);
        ASSERT_TRUE(fs::exists(stem + ".json")) << name;
        Json j = Json::parse(slurp(stem + ".json"));
        views.insert(j["id"].get<std::string>() + "/" + j["name"].get<std::string>());
        EXPECT_EQ(j["image"], name);
        EXPECT_EQ(j["frame"], 1);
        EXPECT_EQ(j["width"], 64);
        EXPECT_EQ(j["height"], 48);
        EXPECT_FALSE(j["unit"].get<std::string>().empty()) << name;
        EXPECT_EQ(j["min"], 0.0);
        EXPECT_GT(j["max"].get<double>(), j["min"].get<double>()) << name;
        EXPECT_LE(j["clipped_pixels"].get<size_t>(), size_t(64 * 48)) << name;
        EXPECT_EQ(j["ramp"].size(), heatRampStops().size());
        if (j["name"] == "stack_overflow") {
            EXPECT_EQ(j["scale"], "fixed") << name;  // a flag: its view fixes the range to [0, 1]
            EXPECT_EQ(j["max"], 1.0);
        } else {
            EXPECT_EQ(j["scale"], "p99") << name;
            EXPECT_GT(j["nonzero_pixels"].get<size_t>(), 0u) << name;
            EXPECT_LE(j["max"].get<double>(), j["data_max"].get<double>()) << name;
            // p99: at most 1 % of the pixels that have a value lie above the scale.
            EXPECT_LE(j["clipped_pixels"].get<double>(), 0.01 * j["nonzero_pixels"].get<double>() + 1) << name;
        }
        auto [w, h] = pngSize(slurp(stem + "_labelled.png"));
        EXPECT_GT(w, 64) << name << ": the labelled copy is the image plus its colour bar";
        EXPECT_GT(h, 48) << name;
    }
    EXPECT_TRUE(views.count("psv/nodes_visited") && views.count("psv/stack_overflow") && views.count("metric_tree/triangle_tests"))
        << views.size() << " views";
}

TEST_F(ReportTest, AContactSheetPerFrameWithImages) {
    EXPECT_FALSE(fs::exists(dir_ + "/contact_f0000.png")); // frame 0 has no images
    auto [w, h] = pngSize(slurp(dir_ + "/contact_f0001.png"));
    // Rows: reference, shadow_map, psv, metric_tree; metric_tree's row is shaded + diff + 4 heat maps.
    EXPECT_GE(w, 6 * 64);
    EXPECT_GE(h, 4 * 48);
}

TEST_F(ReportTest, ReportMarkdownShowsEveryFigure) {
    const std::string md = slurp(dir_ + "/report.md");
    EXPECT_EQ(count(md, "\n## Figures\n"), 1u);
    EXPECT_LT(md.find("## Accuracy"), md.find("## Figures")); // appended after the runner's tables
    std::set<std::string> shown;
    const std::regex image(R"(!\[[^\]]+\]\(([^)\s]+)\))");
    for (auto it = std::sregex_iterator(md.begin(), md.end(), image); it != std::sregex_iterator(); ++it) {
        shown.insert((*it)[1]);
        EXPECT_TRUE(fs::exists(dir_ + "/" + (*it)[1].str())) << (*it)[1];
    }
    EXPECT_EQ(shown, (std::set<std::string>{"plot_frame_time.png", "plot_stages.png", "plot_accuracy.png", "contact_f0001.png"}));
    EXPECT_NE(md.find("(images/psv_f0001_heat_nodes_visited_labelled.png)"), std::string::npos);

    // Drawing the figures again (e.g. by hand, after editing the script) replaces the section.
    std::string out;
    ASSERT_EQ(test::runCommand(std::string(SHADOWLAB_PLOT_PYTHON) + " " + SHADOWLAB_SOURCE_DIR + "/scripts/plot_results.py " + dir_ + " wall", out), 0) << out;
    EXPECT_EQ(slurp(dir_ + "/report.md"), md);
}

/// An HTML page made from a markdown report holds every image of it as a PNG data URI, each table
/// as an HTML table, and nothing that a browser would fetch from elsewhere.
void expectSelfContained(const std::string& html, const std::string& md) {
    for (const char* banned : {"http://", "https://", "<link", "<script", "<iframe", "@import", "url("})
        EXPECT_EQ(html.find(banned), std::string::npos) << banned;
    // Found by hand: std::regex recurses per character and overflows the stack on a data URI.
    size_t images = 0;
    const std::string src = "<img src=\"";
    for (size_t at = html.find(src); at != std::string::npos; at = html.find(src, at + 1), ++images) {
        const std::string uri = html.substr(at + src.size(), std::min<size_t>(html.find('"', at + src.size()) - at - src.size(), 300));
        ASSERT_EQ(uri.rfind("data:image/png;base64,", 0), 0u) << uri.substr(0, 60);
        auto [w, h] = pngSize(base64Decode(uri.substr(22, 200)));
        EXPECT_GT(w, 0);
        EXPECT_GT(h, 0);
    }
    EXPECT_GT(images, 0u);
    EXPECT_EQ(images, count(md, "!["));
    // Each markdown table (a header, then a |---| rule) is an HTML table, numbers right-aligned.
    EXPECT_EQ(count(html, "<table>"), count(md, "\n|---|"));
    EXPECT_NE(html.find("<td class=r>"), std::string::npos);
    EXPECT_NE(html.find("<h2>Figures</h2>"), std::string::npos);
}

TEST_F(ReportTest, ReportHtmlIsSelfContained) {
    expectSelfContained(slurp(dir_ + "/report.html"), slurp(dir_ + "/report.md"));
}

TEST_F(ReportTest, ReportHtmlImagesDecodeInAHeadlessBrowser) {
    // scripts/setup.sh installs chromium, so a missing browser is a failure, not a skip.
    std::string out;
    ASSERT_EQ(test::runCommand("command -v chromium", out), 0) << "chromium is not installed (scripts/setup.sh installs it)";
    // A copy with a probe: once the page has loaded, it records how many images decoded.
    std::string page = slurp(dir_ + "/report.html");
    const std::string probe =
        "<script>window.addEventListener('load', () => { const all = [...document.images];"
        " const ok = all.filter(i => i.complete && i.naturalWidth > 0).length;"
        " document.body.setAttribute('data-decoded', ok + '/' + all.length); });</script>";
    page.insert(page.rfind("</body>"), probe);
    const std::string tmp = test::makeTempDir("report-browser");
    std::ofstream(tmp + "/probe.html") << page;
    const std::string chromium =
        "chromium --headless --no-sandbox --disable-gpu --disable-quic --no-first-run --disable-background-networking"
        " --disable-component-update --disable-sync --user-data-dir=" + tmp + "/profile --virtual-time-budget=5000";
    ASSERT_EQ(test::runCommand("(timeout 60 " + chromium + " --dump-dom file://" + tmp + "/probe.html 2>/dev/null)", out), 0) << out;
    const size_t images = count(page, "<img ");
    ASSERT_GE(images, 4u);
    EXPECT_NE(out.find("data-decoded=\"" + std::to_string(images) + "/" + std::to_string(images) + "\""), std::string::npos)
        << out.substr(0, 2000);
}

TEST(SweepReportTest, MergeReportShowsEveryPlotAndIsSelfContained) {
    // What `sweep merge` hands its script (plan.json, sweep.csv), for 2 × 2 runs of two algorithms
    // with different stages: the report's figures do not depend on how the runs were made.
    const std::string dir = test::makeTempDir("sweep-report");
    Json plan = Json::parse(R"({"name": "tiny", "merge": {"ratios": ["psv/reference"],
      "paper": {"source": "A paper, Table 9", "times_ms": {"psv": 3, "reference": 1.5}}},
      "axes": [{"name": "tris", "scale": "triangles", "labels": ["300", "1200"]},
               {"name": "pcf", "scale": "category", "labels": ["0", "1"]}], "runs": []})");
    std::ostringstream csv;
    csv << "run,index,tris,pcf,triangles,pixels,id,algorithm,measure,kind,value\n";
    int index = 0;
    for (int tris : {300, 1200})
        for (int pcf : {0, 1}) {
            const std::string run = "r" + std::to_string(index);
            plan["runs"].push_back({{"index", index}, {"id", run}, {"status", "complete"}, {"renderer", "llvmpipe"},
                                    {"stage_time_source", "wall"}, {"axes", {{"tris", std::to_string(tris)}, {"pcf", std::to_string(pcf)}}}});
            const std::string prefix = run + "," + std::to_string(index) + "," + std::to_string(tris) + "," + std::to_string(pcf) +
                                       "," + std::to_string(tris) + ",4096,";
            auto row = [&](const std::string& id, const std::string& measure, const std::string& kind, double v) {
                csv << prefix << id << "," << id << "," << measure << "," << kind << "," << v << "\n";
            };
            row("reference", "time_ms.trace", "time", tris * 1e-3);
            row("reference", "time_ms.total", "time", tris * 1e-3);
            row("psv", "time_ms.build", "time", 0.5 + pcf);
            row("psv", "time_ms.traverse", "time", tris * 2e-3);
            row("psv", "time_ms.total", "time", 0.5 + pcf + tris * 2e-3);
            for (const char* id : {"reference", "psv"}) {
                row(id, "memory_bytes", "memory", 1 << 20);
                row(id, "accuracy.mismatch_ratio_max", "accuracy", 0);
            }
            ++index;
        }
    std::ofstream(dir + "/plan.json") << plan.dump(2);
    std::ofstream(dir + "/sweep.csv") << csv.str();
    std::string out;
    ASSERT_EQ(test::runCommand(std::string(SHADOWLAB_PLOT_PYTHON) + " " + SHADOWLAB_SOURCE_DIR + "/scripts/sweep_report.py " + dir, out), 0) << out;
    const std::string md = slurp(dir + "/sweep.md");
    EXPECT_EQ(count(md, "\n## Figures\n"), 1u);
    // merge.paper: the paper's ratio (3 / 1.5) beside each measured one, and ours over it.
    EXPECT_NE(md.find("Paper: A paper, Table 9: psv 3 ms, reference 1.5 ms, ratio 2.00."), std::string::npos) << md;
    EXPECT_NE(md.find("| paper | ours / paper |"), std::string::npos) << md;
    for (const char* plot : {"sweep_tris.png", "sweep_pcf.png", "sweep_stages.png"}) {
        EXPECT_NE(md.find(std::string("](") + plot + ")"), std::string::npos) << plot;
        EXPECT_GT(pngSize(slurp(dir + "/" + plot)).first, 0) << plot;
    }
    expectSelfContained(slurp(dir + "/sweep.html"), md);
    // Merged again (more runs finished, say): one Figures section still.
    ASSERT_EQ(test::runCommand(std::string(SHADOWLAB_PLOT_PYTHON) + " " + SHADOWLAB_SOURCE_DIR + "/scripts/sweep_report.py " + dir, out), 0) << out;
    EXPECT_EQ(slurp(dir + "/sweep.md"), md);
}

} // namespace
} // namespace shadowlab
