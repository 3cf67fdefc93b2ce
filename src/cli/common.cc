#include "src/cli/common.h"

#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>

#include "imusysid/log.h"
#include "imusysid/safe_text.h"

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
  std::cerr << "imusysid " << command
            << ": error: " << EscapeForDisplay(status.message()) << "\n";
  return ExitCodeFor(status);
}

int UsageError(const std::string& command, const std::string& message) {
  std::cerr << "imusysid " << command << ": " << EscapeForDisplay(message)
            << "\nRun 'imusysid " << command << " --help' for usage.\n";
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

Status CheckOutputIsNotInput(const std::string& out_flag,
                             const std::string& out,
                             const std::vector<std::string>& inputs) {
  if (out.empty() || out == "-") return Status::Ok();
  struct stat out_stat;
  if (stat(out.c_str(), &out_stat) != 0) return Status::Ok();  // a new file
  for (const std::string& input : inputs) {
    struct stat in_stat;
    if (input.empty() || input == "-" || stat(input.c_str(), &in_stat) != 0) {
      continue;
    }
    if (S_ISREG(out_stat.st_mode) && in_stat.st_dev == out_stat.st_dev &&
        in_stat.st_ino == out_stat.st_ino) {
      return InvalidArgumentError(out_flag + "='" + out + "' is the input '" +
                                  input +
                                  "'; refusing to replace an input with a "
                                  "result (choose another file)");
    }
  }
  return Status::Ok();
}

StatusOr<nlohmann::json> ReadJsonFile(const std::string& path) {
  StatusOr<std::string> text = ReadFileToString(path);
  if (!text.ok()) return text.status();
  try {
    return nlohmann::json::parse(*text);
  } catch (const nlohmann::json::parse_error& e) {
    // e.byte is 1-based and points just past the offending character.
    const std::size_t at =
        std::min<std::size_t>(e.byte > 0 ? e.byte - 1 : 0, text->size());
    int line = 1;
    std::size_t line_start = 0;
    for (std::size_t i = 0; i < at; ++i) {
      if ((*text)[i] == '\n') {
        ++line;
        line_start = i + 1;
      }
    }
    std::string what = e.what();
    // "[json.exception.parse_error.101] parse error at line 1, column 2: x"
    // → "x": the position is given in the compiler style in front.
    const std::size_t colon = what.find(": ");
    if (colon != std::string::npos) what = what.substr(colon + 2);
    return InvalidArgumentError(path + ":" + std::to_string(line) + ":" +
                                std::to_string(at - line_start + 1) +
                                ": not valid JSON: " + what);
  }
}

std::string DumpJson(const nlohmann::ordered_json& j) {
  return j.dump(
      2, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
}

}  // namespace cli
}  // namespace imusysid
