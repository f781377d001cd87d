#pragma once
// Each subcommand registers its options and callback on the root app; see main.cpp.

#include <CLI/CLI.hpp>

namespace priormap::app {

void AddSimulateCommand(CLI::App& app);
void AddConvertCommand(CLI::App& app);
void AddPlotCommand(CLI::App& app);
void AddPriorCommand(CLI::App& app);
void AddScanCommand(CLI::App& app);
void AddSlamCommand(CLI::App& app);
void AddPrfCommand(CLI::App& app);
/// `prf study`, registered on the prf command by AddPrfCommand.
void AddPrfStudyCommand(CLI::App& prf_cmd);
/// `prf sonar-study`, registered on the prf command by AddPrfCommand.
void AddPrfSonarStudyCommand(CLI::App& prf_cmd);
/// `prf fit-sonar`, registered on the prf command by AddPrfCommand.
void AddPrfFitSonarCommand(CLI::App& prf_cmd);
/// `prf rhat`, registered on the prf command by AddPrfCommand.
void AddPrfRhatCommand(CLI::App& prf_cmd);
void AddGridCommand(CLI::App& app);
void AddDemoCommand(CLI::App& app);
void AddVersionCommand(CLI::App& app);

/// Every subcommand above, as `priormap` has them (main.cpp, and the demo's in-process runs).
void AddAllCommands(CLI::App& app);

}  // namespace priormap::app
