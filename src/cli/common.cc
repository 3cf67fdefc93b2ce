#include "src/cli/common.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "imusysid/log.h"
#include "src/tools/safe_text.h"

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

namespace {
std::vector<std::pair<std::string, std::string>>& FlagValueList() {
  static std::vector<std::pair<std::string, std::string>> values;
  return values;
}
}  // namespace

std::vector<std::string> FlagValues(const std::string& name) {
  std::vector<std::string> out;
  for (const auto& [flag, value] : FlagValueList()) {
    if (flag == name) out.push_back(value);
  }
  return out;
}

void RecordFlagValue(const std::string& name, const std::string& value) {
  FlagValueList().emplace_back(name, value);
}

bool JsonOutput() { return FLAGS_format == "json"; }

Status EmitOutput(const std::string& text, const std::string& path) {
  if (path.empty()) {
    std::cout << EscapeLines(text);
    std::cout.flush();
    return std::cout.good() ? Status::Ok() : IoError("cannot write stdout");
  }
  return WriteFileAtomically(path, text);
}

Status CheckOutputFolderTarget(const std::string& out_flag,
                               const std::string& folder) {
  if (folder.empty()) return Status::Ok();
  std::error_code ec;
  const auto type = std::filesystem::status(folder, ec).type();
  if (type != std::filesystem::file_type::not_found &&
      type != std::filesystem::file_type::directory) {
    return InvalidArgumentError("--out='" + out_flag +
                                "' exists and is not a folder");
  }
  return Status::Ok();
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

std::string EscapeLines(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    const bool has_newline = end != std::string::npos;
    if (!has_newline) end = text.size();
    out += EscapeForDisplay(std::string_view(text).substr(start, end - start));
    if (has_newline) out += '\n';
    start = end + 1;
  }
  return out;
}

std::string DumpJson(const nlohmann::ordered_json& j) {
  return j.dump(
      2, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
}

}  // namespace cli
}  // namespace imusysid
