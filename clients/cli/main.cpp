// bsls: the BSLS command-line tool. One catch-and-map point turns every error
// into one line on stderr and an exit code (see command.h).
#include <cstdio>
#include <exception>
#include <iostream>

#include "bsls/common/errors.h"
#include "command.h"

int main(int argc, char** argv) {
  using namespace bsls::cli;
  CLI::App app{"BSLS: brick structured-light face measurement", "bsls"};
  app.set_version_flag("--version", std::string("bsls ") + BSLS_VERSION);
  app.require_subcommand(1);
  AddProcessCommand(app);
  AddSimulateCommand(app);
  AddEvaluateCommand(app);
  AddCalibrateCommand(app);
  AddSimulateCalibrationCommand(app);
  AddReconstructCommand(app);
  AddMeasureCommand(app);
  AddDeviceCommands(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "bsls: " << e.what() << " (see bsls --help)\n";
    return kExitUsage;
  } catch (const CommandError& e) {
    std::cerr << "bsls: " << e.what() << "\n";
    return e.code();
  } catch (const bsls::InputError& e) {
    std::cerr << "bsls: " << e.what() << "\n";
    return kExitInput;
  } catch (const bsls::OutputError& e) {
    std::cerr << "bsls: " << e.what() << "\n";
    return kExitOutput;
  } catch (const std::exception& e) {
    std::cerr << "bsls: internal error: " << e.what() << "\n";
    return kExitInternal;
  }
  return kExitOk;
}
