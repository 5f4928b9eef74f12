// atmos: significant lines of code, by the rules of Leenman's 2025 thesis section 11.7.
//
// A line counts when it
//   * is not empty (after removing comments and surrounding white space),
//   * is not a comment (// to the end of the line, /* ... */ across lines),
//   * is not bare punctuation: only the characters { } ( ) [ ] ; , (e.g. "}", "});"),
//   * is not setup: preprocessor lines (#include, #pragma, #if/#endif, ...),
//     namespace lines ("namespace x {"), access specifiers ("public:"), and
//     "using namespace" lines.
// String literals are respected (a "//" inside quotes is not a comment).
// A model's own files are src/atmos/models/<name with - replaced by _>.h/.cpp
// and <that>_*.h/.cpp (the naming rule of the project).
#pragma once

#include <string>
#include <vector>

namespace atmos {

int CountSignificantLines(const std::string& source_text);
int CountSignificantLinesInFile(const std::string& path);  // throws atmos::Error if unreadable

// The source files of model `name` under `source_dir` (the repository root), sorted.
std::vector<std::string> ModelSourceFiles(const std::string& source_dir, const std::string& name);

struct ModelLoc {
    std::string model;
    std::vector<std::string> files;  // relative to the source dir
    int lines = 0;
    int thesis_lines =
        -1;  // Leenman's 2025 thesis section 12.4, -1 when the thesis has no such model
    std::string thesis_name;
};
ModelLoc CountModelLoc(const std::string& source_dir, const std::string& name);
// The thesis's count for a model name (Leenman's 2025 thesis section 12.4), or -1.
int ThesisLoc(const std::string& model, std::string* thesis_name = nullptr);
// The repository root: $ATMOS_SOURCE_DIR when set, else the one compiled into
// the library (ATMOS_SOURCE_DIR).
std::string DefaultSourceDir();

}  // namespace atmos
