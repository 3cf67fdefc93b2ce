#include "src/cli_common.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>

#include "src/flight_log.h"

DEFINE_string(format,
              "table",
              "Output format: table (for people) or json (for scripts).");

namespace imusysid {
namespace cli {

int ReportError(const std::string& command, const Status& status) {
  std::cerr << "imusysid " << command << ": error: " << status.message()
            << "\n";
  return status.ExitCode();
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

std::string FormatNumber(double value, int digits) {
  if (std::isnan(value)) return "n/a";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*g", digits, value);
  return buf;
}

std::string FormatTable(const std::vector<std::string>& header,
                        const std::vector<std::vector<std::string>>& rows) {
  std::vector<std::size_t> width(header.size(), 0);
  for (std::size_t i = 0; i < header.size(); ++i) width[i] = header[i].size();
  for (const auto& row : rows) {
    for (std::size_t i = 0; i < row.size() && i < width.size(); ++i) {
      width[i] = std::max(width[i], row[i].size());
    }
  }
  std::ostringstream out;
  auto emit = [&](const std::vector<std::string>& row) {
    std::string line;
    for (std::size_t i = 0; i < width.size(); ++i) {
      const std::string cell = i < row.size() ? row[i] : "";
      line += cell;
      if (i + 1 < width.size())
        line += std::string(width[i] - cell.size() + 2, ' ');
    }
    while (!line.empty() && line.back() == ' ') line.pop_back();
    out << line << "\n";
  };
  emit(header);
  std::vector<std::string> rule;
  for (std::size_t w : width) rule.push_back(std::string(w, '-'));
  emit(rule);
  for (const auto& row : rows) emit(row);
  return out.str();
}

}  // namespace cli
}  // namespace imusysid
