// atmos: the command-line tool (contract in DESIGN.md, "The command line").
//
// Every failure prints one line, "atmos: error: ...", on stderr and exits with
// status 2 (usage and input errors) or 1 (anything else unexpected). Each
// subcommand registers itself from its own file (cli_common.h).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "atmos/error.h"
#include "cli_common.h"

int main(int argc, char** argv) {
    using namespace atmos::cli;
    CLI::App app{
        "atmos: atmospheric scattering models, a path-traced reference and their comparison"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "atmos 0.1.0");
    const std::vector<Command> commands = {
        AddListCommand(&app),
        AddRenderCommand(&app),
        AddSampleCommand(&app),
        AddBakeCommand(&app),
        AddFlipCommand(&app),
        AddRmseCommand(&app),
        AddCompareCommand(&app, argc, argv),
        AddBenchCommand(&app),
        AddLocCommand(&app),
        AddFitCommand(&app),
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
            if (c.app->parsed()) return c.run();
        }
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        std::fprintf(stderr, "atmos: error: %s\n", e.what());
        return 2;
    } catch (const atmos::Error& e) {
        std::fprintf(stderr, "atmos: error: %s\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "atmos: error: %s\n", e.what());
        return 1;
    }
    return 0;
}
