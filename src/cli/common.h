// Shared plumbing for the imusysid command-line tool: subcommand table,
// per-command --help generated from the gflags definitions, strict flag
// parsing (unknown flags and bad values are usage errors, exit code 2), and
// error/JSON output helpers.

#ifndef IMUSYSID_SRC_CLI_COMMON_H_
#define IMUSYSID_SRC_CLI_COMMON_H_

#include <string>
#include <utility>
#include <vector>

#include "gflags/gflags.h"
#include "imusysid/report.h"
#include "imusysid/status.h"
#include "nlohmann/json.hpp"

DECLARE_string(format);

namespace imusysid {
namespace cli {

// Exit codes of the tool.
inline constexpr int kExitOk = 0;
inline constexpr int kExitInternal = 1;
inline constexpr int kExitBadInput = 2;

struct Command {
  std::string name;
  std::string summary;  // one line for the command list
  std::string usage;    // "imusysid fit --log=FILE [flags]"
  std::string details;  // paragraphs printed by --help after the usage
  std::vector<std::string> flags;  // gflags names this command accepts
  // Runs with the positional arguments; flags are already set.
  int (*run)(const std::vector<std::string>& positional) = nullptr;
  // Also takes every option the estimators declare (estimator_flags.h).
  bool estimator_flags = false;
  // Defaults this command gives a shared flag when it is not set, where
  // they differ from the flag's own (--help shows these): {name, value}.
  std::vector<std::pair<std::string, std::string>> defaults = {};
};

// Every subcommand, in help order. Each cli_<name>.cc defines one accessor.
const Command& SimulateCommand();
const Command& InspectCommand();
const Command& FitCommand();
const Command& DisplacementCommand();
const Command& ExportProblemCommand();
const Command& ConvertCommand();
const Command& BenchCommand();
const Command& TrackCommand();
const Command& PlanCommand();

// The process exit code for a status: 0 for OK, 2 for the user's input
// (invalid argument, not found, failed precondition), 1 otherwise.
int ExitCodeFor(const Status& status);

// Prints "imusysid <cmd>: error: <message>" to stderr and returns the exit
// code for the status (2 for bad input, 1 otherwise). The message is escaped
// (EscapeForDisplay): it may quote bytes from the user's files.
int ReportError(const std::string& command, const Status& status);

// Usage error: prints the message and a hint to --help, returns 2.
int UsageError(const std::string& command, const std::string& message);

// True when the flag was given on the command line (gflags' is_default
// cannot tell for NaN defaults). Recorded by the parser in cli_main.cc.
bool FlagWasSet(const std::string& name);
void MarkFlagSet(const std::string& name);
// Every value the flag was given, in command-line order (gflags keeps the
// last only; `fit` reads each --log). Recorded by the same parser.
std::vector<std::string> FlagValues(const std::string& name);
void RecordFlagValue(const std::string& name, const std::string& value);

// The value of --format: "table" or "json" (validated by the parser).
bool JsonOutput();

// Writes `text` to stdout (line by line through EscapeLines); when `path` is
// not empty, writes it as it is to that file
// instead (WriteFileAtomically: atomic for regular files, through symbolic
// links, streamed into "-", FIFOs and devices).
Status EmitOutput(const std::string& text, const std::string& path);

// InvalidArgument when `out` names the same file as one of `inputs` (the
// same device and inode): replacing a log with a result would destroy it.
Status CheckOutputIsNotInput(const std::string& out_flag,
                             const std::string& out,
                             const std::vector<std::string>& inputs);

// InvalidArgument naming --out=`out_flag` when `folder` exists and is not a
// folder: checked before long work, since a file in the way of an output
// folder would fail only at the end.
Status CheckOutputFolderTarget(const std::string& out_flag,
                               const std::string& folder);

// `text` with each line escaped by EscapeForDisplay (control bytes and
// invalid UTF-8 as \xNN), the line ends kept: for tables that quote strings
// from files (a ULog's vehicle name, a CSV's column names).
std::string EscapeLines(const std::string& text);

// `j` as indented text; strings that are not valid UTF-8 (a ULog's info
// field in Latin-1) have their bad bytes replaced by U+FFFD rather than
// making the JSON library throw.
std::string DumpJson(const nlohmann::ordered_json& j);

}  // namespace cli
}  // namespace imusysid

#endif  // IMUSYSID_SRC_CLI_COMMON_H_
