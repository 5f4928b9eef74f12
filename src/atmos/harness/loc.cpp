// atmos: significant lines of code (Leenman's 2025 thesis section 11.7; rules in loc.h).
#include "harness/loc.h"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "atmos/error.h"
#include "atmos/model.h"
#include "io/bounded_read.h"

namespace fs = std::filesystem;

namespace atmos {

namespace {

std::string Trim(const std::string& s) {
    const size_t a = s.find_first_not_of(" \t\r\f\v");
    if (a == std::string::npos) return "";
    const size_t b = s.find_last_not_of(" \t\r\f\v");
    return s.substr(a, b - a + 1);
}

bool StartsWith(const std::string& s, const std::string& prefix) {
    return s.compare(0, prefix.size(), prefix) == 0;
}

bool IsSetup(const std::string& code) {
    if (code[0] == '#') return true;
    if (StartsWith(code, "namespace ") || code == "namespace {" || code == "namespace{") {
        return true;
    }
    if (code == "public:" || code == "private:" || code == "protected:") return true;
    return StartsWith(code, "using namespace ");
}

}  // namespace

int CountSignificantLines(const std::string& text) {
    std::istringstream in(text);
    std::string line;
    bool in_block_comment = false;
    int count = 0;
    while (std::getline(in, line)) {
        // Strip comments, keeping string and character literals.
        std::string code;
        char quote = 0;
        for (size_t i = 0; i < line.size(); ++i) {
            const char c = line[i];
            const char next = i + 1 < line.size() ? line[i + 1] : '\0';
            if (in_block_comment) {
                if (c == '*' && next == '/') {
                    in_block_comment = false;
                    ++i;
                }
                continue;
            }
            if (quote != 0) {
                code += c;
                if (c == '\\' && i + 1 < line.size()) {
                    code += next;
                    ++i;
                } else if (c == quote) {
                    quote = 0;
                }
                continue;
            }
            if (c == '/' && next == '/') break;
            if (c == '/' && next == '*') {
                in_block_comment = true;
                ++i;
                code += ' ';
                continue;
            }
            if (c == '"' || c == '\'') quote = c;
            code += c;
        }
        code = Trim(code);
        if (code.empty()) continue;
        if (code.find_first_not_of("{}()[];, \t") == std::string::npos) continue;
        if (IsSetup(code)) continue;
        ++count;
    }
    return count;
}

int CountSignificantLinesInFile(const std::string& path) {
    // Bounded (io/bounded_read.h): `loc --file /dev/zero` grew without end.
    return CountSignificantLines(ReadFileBounded(path, kMaxSourceFileBytes));
}

namespace {
// The registered model a name or spec ("bruneton:orders=2") stands for, or null.
const ModelInfo* RegisteredInfo(const std::string& model) {
    const std::string name = model.substr(0, model.find(':'));
    for (const ModelInfo& info : ListModels()) {
        if (info.name == name) return &GetModelInfo(name);
    }
    return nullptr;
}
}  // namespace

std::vector<std::string> ModelSourceFiles(const std::string& source_dir, const std::string& name) {
    const ModelInfo* info = RegisteredInfo(name);
    std::string stem = info != nullptr && !info->source_stem.empty() ? info->source_stem : name;
    std::replace(stem.begin(), stem.end(), '-', '_');
    std::vector<std::string> files;
    const fs::path dir = fs::path(source_dir) / "src" / "atmos" / "models";
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) return files;
    for (const auto& entry : fs::directory_iterator(dir, ec)) {
        if (!entry.is_regular_file()) continue;
        const std::string file = entry.path().filename().string();
        const std::string ext = entry.path().extension().string();
        if (ext != ".h" && ext != ".cpp" && ext != ".cu") continue;
        const std::string base = entry.path().stem().string();
        if (base == stem || StartsWith(base, stem + "_")) {
            files.push_back((fs::path("src") / "atmos" / "models" / file).string());
        }
    }
    std::sort(files.begin(), files.end());
    return files;
}

int ThesisLoc(const std::string& model, std::string* thesis_name) {
    // Leenman's 2025 thesis section 12.4, "significant lines of code", as each model declares it.
    const ModelInfo* info = RegisteredInfo(model);
    if (info == nullptr || info->thesis_lines < 0) return -1;
    if (thesis_name != nullptr) *thesis_name = info->thesis_name;
    return info->thesis_lines;
}

ModelLoc CountModelLoc(const std::string& source_dir, const std::string& name) {
    ModelLoc loc;
    loc.model = name;
    loc.files = ModelSourceFiles(source_dir, name);
    for (const std::string& f : loc.files) {
        loc.lines += CountSignificantLinesInFile((fs::path(source_dir) / f).string());
    }
    loc.thesis_lines = ThesisLoc(name, &loc.thesis_name);
    return loc;
}

std::string DefaultSourceDir() {
    // A binary run from another checkout (scripts/gpu_bundle.sh) is told where
    // the sources are by the environment.
    if (const char* env = std::getenv("ATMOS_SOURCE_DIR"); env && *env) return env;
#ifdef ATMOS_SOURCE_DIR
    return ATMOS_SOURCE_DIR;
#else
    return ".";
#endif
}

}  // namespace atmos
