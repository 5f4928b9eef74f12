// atmos: the command-line tool (contract in DESIGN.md, "The command line").
//
// Every failure prints one line, "atmos: error: ...", on stderr and exits with
// status 2 (issue 38 item 6: out of memory and unexpected exceptions too). Each
// subcommand registers itself from its own file (cli_common.h).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <memory>
#include <new>
#include <string>
#include <vector>

#include "atmos/error.h"
#include "cli_common.h"
#include "harness/listing.h"
#include "harness/mpi_world.h"

namespace {

int RunCommand(int argc, char** argv) {
    using namespace atmos::cli;
    CLI::App app{
        "atmos: atmospheric scattering models, a path-traced reference and their comparison"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "atmos 0.1.0");
    const std::vector<Command> commands = {
        AddListCommand(&app),
        AddRenderCommand(&app),
        AddMergeCommand(&app),
        AddSampleCommand(&app),
        AddIrradianceCommand(&app),
        AddBakeCommand(&app),
        AddViewerCommand(&app),
        AddFlipCommand(&app),
        AddRmseCommand(&app),
        AddCompareCommand(&app, argc, argv),
        AddBenchCommand(&app),
        AddLocCommand(&app),
        AddFitCommand(&app),
        AddValidateCommand(&app),
        AddReferenceProvenanceCommand(&app),
        AddSunCommand(&app),
    };
    try {
        if (argc > 1 && argv[1][0] != '-') {
            bool known = false;
            std::string names;
            for (const Command& c : commands) {
                known |= c.app->get_name() == argv[1];
                names += (names.empty() ? "" : ", ") + c.app->get_name();
            }
            if (!known) atmos::Fail("unknown command '", argv[1], "' (commands: ", names, ")");
        }
        app.parse(argc, argv);
        for (const Command& c : commands) {
            if (!c.app->parsed()) continue;
            const int status = c.run();
            const int64_t guarded = atmos::OutputGuardCount();
            if (guarded > 0) {
                const bool strict = StrictRequested();
                std::fprintf(stderr,
                             "atmos: %s: %lld output value(s) were NaN, infinite or negative and "
                             "were written as 0 (a defect: please report it with the command "
                             "line)\n",
                             strict ? "error" : "warning", static_cast<long long>(guarded));
                if (strict) return 2;
            }
            return status;
        }
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ExtrasError& e) {
        // A model option written as a flag (the syntax before issue 14)?
        const std::string hint =
            atmos::ModelOptionFlagHint(std::vector<std::string>(argv + 1, argv + argc));
        std::fprintf(stderr, "atmos: error: %s%s\n", e.what(), hint.c_str());
        return 2;
    } catch (const CLI::ParseError& e) {
        std::fprintf(stderr, "atmos: error: %s\n", e.what());
        return 2;
    } catch (const atmos::Error& e) {
        std::fprintf(stderr, "atmos: error: %s\n", e.what());
        return 2;
    } catch (const std::filesystem::filesystem_error& e) {
        // A file system failure is an input error (a missing or unwritable
        // path): one line naming the path, not the library's raw text.
        std::string paths = e.path1().string();
        if (!e.path2().empty()) paths += "' -> '" + e.path2().string();
        std::fprintf(stderr, "atmos: error: '%s': %s\n", paths.c_str(), e.code().message().c_str());
        return 2;
    } catch (const std::bad_alloc&) {
        // An input too large for this machine's memory (issue 38 item 6).
        std::fprintf(stderr,
                     "atmos: error: out of memory (an input or size too large for this "
                     "machine)\n");
        return 2;
    } catch (const std::exception& e) {
        std::string what = e.what();
        std::replace(what.begin(), what.end(), '\n', ' ');  // one line
        // A JSON library exception that escaped a parser: malformed input.
        const std::string json_tag = "[json.exception.";
        if (what.rfind(json_tag, 0) == 0) {
            const size_t end = what.find("] ");
            std::fprintf(stderr, "atmos: error: invalid JSON: %s\n",
                         end == std::string::npos ? what.c_str() : what.c_str() + end + 2);
            return 2;
        }
        std::fprintf(stderr, "atmos: error: %s\n", what.c_str());
        return 2;
    } catch (...) {
        std::fprintf(stderr, "atmos: error: an unexpected failure (not a standard exception)\n");
        return 2;
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    // Under an MPI launcher (mpirun, srun): MPI for the process's life; a
    // failure on one rank ends them all (mpi_world.h).
    std::unique_ptr<atmos::MpiSession> mpi;
    try {
        mpi = std::make_unique<atmos::MpiSession>(&argc, &argv);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "atmos: error: %s\n", e.what());
        return 2;
    }
    const int status = RunCommand(argc, argv);
    if (status != 0) mpi->Abort(status);
    return status;
}
