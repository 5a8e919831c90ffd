// Expectations on a summary: bounds met and missed (by how much), ratios between ids, measures not
// taken, and the JUnit file holding any experiment name as text.
#include "framework/experiment/Config.h"

#include <gtest/gtest.h>

namespace shadowlab {
namespace {

Json summaryWith(double psvMismatch, double psvTotal, double bvhTotal) {
    auto entry = [](Json accuracy, double total) {
        return Json{{"accuracy", accuracy}, {"overflow", 0}, {"memory_bytes", 1000},
                    {"time_ms", {{"total", {{"mean", total}, {"median", total}, {"min", total}, {"max", total}}}}},
                    {"counters", {{"nodes", {{"mean", 5.0}, {"median", 5.0}, {"min", 5.0}, {"max", 5.0}}}}}};
    };
    return {{"algorithms",
             {{"psv", entry({{"mismatch_ratio_max", psvMismatch}, {"rmse", 0.0}}, psvTotal)},
              {"bvh_raytrace", entry(Json(), bvhTotal)},  // accuracy null: no frame had a lit pixel
              {"shadow_map", entry({{"mismatch_ratio_max", 0.002}, {"rmse", 0.01}}, 1.0)}}}};
}

std::vector<Expectation> parse(const std::string& expect, ExpectationIds ids) {
    Json config = {{"expect", Json::parse(expect)}};
    Json resolved = Json::object();
    JsonNode root("c.json", &config, "", &resolved);
    return parseExpectations(root, ids);
}

ExpectationIds ids() {
    ExpectationIds i;
    i.all = {"shadow_map", "psv", "bvh_raytrace"};
    i.exact = {"psv", "bvh_raytrace"};
    i.reference = true;
    return i;
}

TEST(ExpectationsTest, BoundsAreCheckedPerIdWithHowFarTheyMissed) {
    const auto e = parse(R"([{"id": "*exact", "measure": "accuracy.mismatch_ratio_max", "max": 0},
                             {"id": "psv", "measure": "time_ms.total.median", "relative_to": "bvh_raytrace", "max": 1.5},
                             {"id": "*", "measure": "counters.nodes.mean", "min": 4, "max": 6}])", ids());
    const Json ok = checkExpectations(e, ids(), summaryWith(0.0, 3.0, 2.5));
    ASSERT_EQ(ok.size(), 2u + 1u + 3u);
    EXPECT_TRUE(ok[0]["passed"].get<bool>()) << ok.dump(2);
    // bvh_raytrace's accuracy is null: not measured is a failure, never a pass.
    EXPECT_FALSE(ok[1]["passed"].get<bool>());
    // Named by its id first (probe 26: "*" printed one identical line per id).
    EXPECT_EQ(ok[1]["why"].get<std::string>().rfind("bvh_raytrace: not measured: bvh_raytrace has no accuracy.mismatch_ratio_max", 0), 0u)
        << ok[1].dump();
    EXPECT_TRUE(ok[2]["passed"].get<bool>());
    EXPECT_DOUBLE_EQ(ok[2]["value"].get<double>(), 1.2);
    for (size_t k = 3; k < 6; ++k) EXPECT_TRUE(ok[k]["passed"].get<bool>()) << ok[k].dump();

    const Json bad = checkExpectations(e, ids(), summaryWith(0.004, 6.0, 2.0));
    EXPECT_FALSE(bad[0]["passed"].get<bool>());
    EXPECT_EQ(bad[0]["why"], "psv: accuracy.mismatch_ratio_max = 0.004, above max 0");
    EXPECT_EQ(bad[2]["why"], "psv: time_ms.total.median / bvh_raytrace's = 3, above max 1.5 (2×)");
    EXPECT_FALSE(allPassed(bad));
    EXPECT_EQ(expectationLine(bad[2]), "psv: time_ms.total.median / bvh_raytrace's = 3, above max 1.5 (2×) (/expect/1)");
}

// Seventh probe: a negative bound printed a meaningless ratio, "above max -1 (-0×)".
// Fifteenth probe: "*exact" in a run without an exact algorithm was "all 0 met" (a CI guard that
// checks nothing), and "*" relative to psv passed psv against itself with 1.
TEST(ExpectationsTest, AWildcardStandsForAtLeastOneIdAndNeverItsRelativeTo) {
    ExpectationIds only = ids();
    only.all = {"shadow_map"};
    only.exact = {};
    try {
        parse(R"([{"id": "*exact", "measure": "accuracy.mismatch_ratio_max", "max": 0}])", only);
        ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
        EXPECT_EQ(e.jsonPath(), "/expect/0/id");
        EXPECT_NE(e.cause().find("stands for no algorithm"), std::string::npos) << e.what();
    }
    EXPECT_THROW(parse(R"([{"id": "*", "measure": "time_ms.total.mean", "relative_to": "shadow_map", "max": 2}])", only), InputError);
    const auto e = parse(R"([{"id": "*", "measure": "time_ms.total.mean", "relative_to": "psv", "max": 2}])", ids());
    EXPECT_EQ(idsOf(e[0], ids()), (std::vector<std::string>{"shadow_map", "bvh_raytrace"}));
}

TEST(ExpectationsTest, ARatioToTheBoundOnlyWhereBothArePositive) {
    const auto e = parse(R"([{"id": "psv", "measure": "overflow", "max": -1}])", ids());
    const Json r = checkExpectations(e, ids(), summaryWith(0.0, 3.0, 2.5));
    EXPECT_EQ(r[0]["why"], "psv: overflow = 0, above max -1");
}

TEST(ExpectationsTest, AStageOrCounterTheRunDidNotMeasureFailsNamingWhatItHas) {
    const auto e = parse(R"([{"id": "psv", "measure": "time_ms.buidl.median", "max": 9}])", ids());
    const Json r = checkExpectations(e, ids(), summaryWith(0, 1, 1));
    ASSERT_EQ(r.size(), 1u);
    EXPECT_FALSE(r[0]["passed"].get<bool>());
    EXPECT_NE(r[0]["why"].get<std::string>().find("buidl is not among: total"), std::string::npos) << r[0].dump();
}

TEST(ExpectationsTest, JUnitHoldsTheNameAsText) {
    const auto e = parse(R"([{"id": "psv", "measure": "overflow", "max": 0}, {"id": "psv", "measure": "memory_bytes", "max": 10}])", ids());
    const Json r = checkExpectations(e, ids(), summaryWith(0, 1, 1));
    const std::string xml = expectationsJUnit("a<b>&\"c\" ]]> 'd'", r, 1.5);
    EXPECT_NE(xml.find("name=\"shadowlab expectations: a&lt;b&gt;&amp;&quot;c&quot; ]]&gt; &apos;d&apos;\""), std::string::npos) << xml;
    EXPECT_NE(xml.find("tests=\"2\" failures=\"1\""), std::string::npos) << xml;
    EXPECT_NE(xml.find("<failure message=\"psv: memory_bytes = 1000, above max 10 (100×)\">"), std::string::npos) << xml;
    EXPECT_EQ(xml.find("<b>"), std::string::npos);
}

} // namespace
} // namespace shadowlab
