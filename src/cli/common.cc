#include "src/cli/common.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>

#include "imusysid/log.h"

DEFINE_string(format,
              "table",
              "Output format: table (for people) or json (for scripts).");

namespace imusysid {
namespace cli {

int ExitCodeFor(const Status& status) {
  switch (status.code()) {
    case StatusCode::kOk:
      return kExitOk;
    case StatusCode::kInvalidArgument:
    case StatusCode::kNotFound:
    case StatusCode::kFailedPrecondition:
      return kExitBadInput;
    case StatusCode::kIoError:
    case StatusCode::kInternal:
      return kExitInternal;
  }
  return kExitInternal;
}

int ReportError(const std::string& command, const Status& status) {
  std::cerr << "imusysid " << command << ": error: " << status.message()
            << "\n";
  return ExitCodeFor(status);
}

int UsageError(const std::string& command, const std::string& message) {
  std::cerr << "imusysid " << command << ": " << message << "\nRun 'imusysid "
            << command << " --help' for usage.\n";
  return kExitBadInput;
}

namespace {
std::vector<std::string>& SetFlags() {
  static std::vector<std::string> flags;
  return flags;
}
}  // namespace

bool FlagWasSet(const std::string& name) {
  const auto& flags = SetFlags();
  return std::find(flags.begin(), flags.end(), name) != flags.end();
}

void MarkFlagSet(const std::string& name) { SetFlags().push_back(name); }

bool JsonOutput() { return FLAGS_format == "json"; }

Status EmitOutput(const std::string& text, const std::string& path) {
  if (path.empty()) {
    std::cout << text;
    std::cout.flush();
    return std::cout.good() ? Status::Ok() : IoError("cannot write stdout");
  }
  return WriteFileAtomically(path, text);
}

}  // namespace cli
}  // namespace imusysid
