// The parameter table in each docs/algorithms/NAME.md is the algorithm's schema, as
// `shadowlab list --markdown NAME` prints it: a doc can never disagree with the code it documents,
// and every algorithm, the template too, has one. With SHADOWLAB_UPDATE_DOCS=1 the test rewrites
// the tables instead (scripts/update_param_docs.py runs it so).
#include "algorithms/template/Template.h"
#include "framework/algorithm/ShadowAlgorithm.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

namespace shadowlab {
namespace {

const std::string kBegin = "<!-- parameters: generated from the schema by scripts/update_param_docs.py; do not edit -->\n";
const std::string kEnd = "<!-- end of parameters -->";

void expectDocMatchesSchema(const AlgorithmInfo& info) {
    const std::string path = std::string(SHADOWLAB_SOURCE_DIR) + "/docs/algorithms/" + info.name + ".md";
    std::ifstream in(path);
    ASSERT_TRUE(in) << path << " is missing: every algorithm has a doc with its parameter table";
    std::stringstream text;
    text << in.rdbuf();
    const std::string doc = text.str();
    const size_t begin = doc.find(kBegin), end = doc.find(kEnd);
    ASSERT_NE(begin, std::string::npos) << path << " has no parameter table markers";
    ASSERT_NE(end, std::string::npos) << path << " has no end marker";
    if (const char* update = std::getenv("SHADOWLAB_UPDATE_DOCS"); update && std::string(update) == "1") {
        std::ofstream(path) << doc.substr(0, begin + kBegin.size()) + info.schema().markdownTable() + doc.substr(end);
        return;
    }
    EXPECT_EQ(doc.substr(begin + kBegin.size(), end - begin - kBegin.size()), info.schema().markdownTable())
        << path << " disagrees with the schema: run scripts/update_param_docs.py";
}

TEST(ParamDocsTest, EveryRegisteredAlgorithmsDocTableIsItsSchema) {
    for (const AlgorithmInfo& info : algorithmRegistry()) {
        SCOPED_TRACE(info.name);
        expectDocMatchesSchema(info);
    }
}

TEST(ParamDocsTest, TheTemplatesDocTableIsItsSchema) { expectDocMatchesSchema(templateInfo()); }

} // namespace
} // namespace shadowlab
