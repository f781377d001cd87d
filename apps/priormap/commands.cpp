#include "commands.hpp"

#include "cli_support.hpp"

namespace priormap::app {

void AddAllCommands(CLI::App& app) {
  AddSimulateCommand(app);
  AddConvertCommand(app);
  AddPlotCommand(app);
  AddPriorCommand(app);
  AddScanCommand(app);
  AddSlamCommand(app);
  AddPrfCommand(app);
  AddGridCommand(app);
  AddDemoCommand(app);
  AddVersionCommand(app);
  RefuseNonFiniteNumbers(app);
}

}  // namespace priormap::app
