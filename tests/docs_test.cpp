// The docs match the code: each model's option table in docs/models/*.md (between
// `<!-- options:begin NAME -->` and `<!-- options:end NAME -->`) is the table its
// OptionTable generates (scripts/gen_option_docs.py rewrites them), and every
// registered model has exactly one such table.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "atmos/model.h"

namespace atmos {
namespace {

namespace fs = std::filesystem;

std::map<std::string, std::string> DocumentedTables() {
    std::map<std::string, std::string> tables;
    const fs::path dir = fs::path(ATMOS_SOURCE_DIR) / "docs" / "models";
    for (const auto& entry : fs::directory_iterator(dir)) {
        if (entry.path().extension() != ".md") continue;
        std::ifstream in(entry.path());
        std::stringstream ss;
        ss << in.rdbuf();
        const std::string text = ss.str();
        const std::string begin = "<!-- options:begin ";
        for (size_t at = text.find(begin); at != std::string::npos; at = text.find(begin, at + 1)) {
            const size_t name_end = text.find(" -->\n", at);
            const std::string name = text.substr(at + begin.size(), name_end - at - begin.size());
            const size_t body = name_end + 5;
            const size_t end = text.find("<!-- options:end " + name + " -->", body);
            EXPECT_NE(end, std::string::npos) << entry.path() << ": no end marker for " << name;
            EXPECT_EQ(tables.count(name), 0u) << name << " documented twice";
            tables[name] = text.substr(body, end - body);
        }
    }
    return tables;
}

TEST(Docs, OptionTablesMatchTheCode) {
    const std::map<std::string, std::string> documented = DocumentedTables();
    for (const ModelInfo& info : ListModels()) {
        auto it = documented.find(info.name);
        ASSERT_NE(it, documented.end()) << "docs/models has no option table for " << info.name;
        EXPECT_EQ(it->second, OptionsMarkdown(info.options))
            << "docs/models: the option table of " << info.name
            << " differs from the code; run scripts/gen_option_docs.py";
    }
    EXPECT_EQ(documented.size(), ListModels().size()) << "a documented table names no model";
}

}  // namespace
}  // namespace atmos
