// The subcommands of `bsls` and the one error type they report through.
//
// Exit codes scripts can rely on:
//   0  done
//   1  the input was read but could not be processed (e.g. no reference line)
//   2  the command line is wrong
//   3  an input file is missing, unreadable or not usable
//   4  an output file could not be written
//   5  a service could not be reached, or did not answer in time (try again)
//   6  a service refused the caller (no certificate, or a role without the right)
//   7  a service could not do it (device failed, disk full, damaged frame)
//   70 an internal error (a bug: please report it)
#ifndef BSLS_CLIENTS_CLI_COMMAND_H_
#define BSLS_CLIENTS_CLI_COMMAND_H_

#include <CLI/CLI.hpp>
#include <stdexcept>
#include <string>

namespace bsls::cli {

enum ExitCode : int {
  kExitOk = 0,
  kExitNotProcessed = 1,
  kExitUsage = 2,
  kExitInput = 3,
  kExitOutput = 4,
  kExitUnavailable = 5,
  kExitRefused = 6,
  kExitServiceFailed = 7,
  kExitInternal = 70,
};

// A command that cannot do its job: main prints what() as one line on stderr
// and exits with code().
class CommandError : public std::runtime_error {
 public:
  CommandError(ExitCode code, const std::string& message)
      : std::runtime_error(message), code_(code) {}
  ExitCode code() const { return code_; }

 private:
  ExitCode code_;
};

// Adds `bsls process` to the application.
void AddProcessCommand(CLI::App& app);
// Adds `bsls simulate` to the application.
void AddSimulateCommand(CLI::App& app);
// Adds `bsls evaluate` to the application.
void AddEvaluateCommand(CLI::App& app);
// Adds `bsls calibrate` to the application.
void AddCalibrateCommand(CLI::App& app);
// Adds `bsls simulate-calibration` to the application.
void AddSimulateCalibrationCommand(CLI::App& app);
// Adds `bsls reconstruct` to the application.
void AddReconstructCommand(CLI::App& app);
// Adds `bsls measure` to the application.
void AddMeasureCommand(CLI::App& app);
// Adds the capture daemon's commands: `bsls status`, `camera`, `gain`,
// `slide`, `grab`, `captures`, `preview`.
void AddDeviceCommands(CLI::App& app);

// The whole file; CommandError (exit 3) naming `option` and `path` when it
// cannot be read.
std::string ReadInputFile(const std::string& path, const std::string& option);

// The whole calibration file, checked: CommandError (exit 3) naming the file
// and the reason when it cannot be read or is not a calibration.
std::string ReadCalibrationFile(const std::string& path, const std::string& option);

}  // namespace bsls::cli

#endif  // BSLS_CLIENTS_CLI_COMMAND_H_
