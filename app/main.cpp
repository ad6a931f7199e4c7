// vplview entry point: `vplview [SCENE]` opens the viewer, subcommands run headless jobs.
// Every user mistake ends here as one line on stderr and exit status 2 (DESIGN.md §3).
#include <cstdio>
#include <exception>
#include <CLI/CLI.hpp>
#include "app/commands.h"
#include "render/core/error.h"

int main(int argc, char** argv) {
  CLI::App app{"vplview: interactive GPU-less global illumination (VPL preview + VPL-guided path tracing)"};
  app.require_subcommand(0, 1);
  vpl::app::registerCommands(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "vplview: %s (see vplview --help)\n", e.what());
    return 2;
  }
  try {
    return vpl::app::runSelectedCommand(app);
  } catch (const vpl::InputError& e) {
    std::fprintf(stderr, "vplview: %s\n", e.what());
    return 2;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "vplview: out of memory\n");
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "vplview: internal error: %s\n", e.what());
    return 1;
  }
}
