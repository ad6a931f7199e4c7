// The subcommands of the vplview executable and their wiring.
#pragma once
#include <CLI/CLI.hpp>

namespace vpl::app {

// Adds every subcommand (render, bench, ...) and the viewer's own options to the app.
void registerCommands(CLI::App& app);
// Runs whichever command the parsed arguments selected; returns the exit status.
int runSelectedCommand(CLI::App& app);

}  // namespace vpl::app
