// The imusysid command-line tool: `imusysid <command> [flags] [args]`.
// Flags are parsed here, strictly: a flag the command does not take, a
// malformed value or a missing value is a usage error (exit code 2), never
// silently ignored. `--help` on any command prints that command's flags.

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <new>
#include <string>
#include <vector>

#include "gflags/gflags.h"
#include "glog/logging.h"
#include "imusysid/version.h"
#include "nlohmann/json.hpp"
#include "src/cli/common.h"
#include "src/cli/estimator_flags.h"
#include "src/tools/safe_text.h"

namespace imusysid {
namespace cli {
namespace {

std::vector<const Command*> AllCommands() {
  return {
      &SimulateCommand(),
      &InspectCommand(),
      &FitCommand(),
      &DisplacementCommand(),
      &ExportProblemCommand(),
      &ConvertCommand(),
      &TrackCommand(),
      &PlanCommand(),
#ifdef IMUSYSID_CLI_HAS_BENCH
      &BenchCommand(),
#endif
  };
}

void PrintToolHelp() {
  std::cout << "imusysid: identify an IMU's position and tilt relative to a "
               "multicopter's centre of mass,\nand its drag coefficient, from "
               "a flight log.\n\nUsage: imusysid <command> [flags] [args]\n\n"
               "Commands:\n";
  for (const Command* c : AllCommands()) {
    std::printf("  %-14s %s\n", c->name.c_str(), c->summary.c_str());
  }
  std::cout << "\nRun 'imusysid <command> --help' for a command's flags.\n"
               "Exit codes: 0 ok, 1 internal error, 2 bad input or usage.\n";
}

void PrintCommandHelp(const Command& c) {
  std::cout << c.summary << "\n\nUsage: " << c.usage << "\n";
  if (!c.details.empty()) std::cout << "\n" << c.details << "\n";
  std::cout << "\nFlags:\n";
  for (const std::string& name : c.flags) {
    gflags::CommandLineFlagInfo info;
    if (!gflags::GetCommandLineFlagInfo(name.c_str(), &info)) continue;
    std::string head = "  --" + name;
    if (info.type != "bool")
      head += "=" + (info.type == "string"   ? std::string("TEXT")
                     : info.type == "double" ? std::string("NUM")
                                             : std::string("INT"));
    std::cout << head << "\n      " << info.description;
    // A shared flag (--format, --imu) may mean something else by default
    // here than its declaration says: the command's own default wins.
    std::string default_value = info.default_value;
    for (const auto& [flag, value] : c.defaults) {
      if (flag == name) default_value = value;
    }
    if (!default_value.empty()) {
      std::cout << " (default: " << default_value << ")";
    }
    std::cout << "\n";
  }
  std::cout << "  --help\n      Show this help.\n";
  if (c.estimator_flags) {
    std::cout << "\nEstimator flags (declared by the estimators that use "
                 "them):\n"
              << EstimatorFlagsHelp();
  }
}

bool Accepts(const Command& c, const std::string& name) {
  for (const auto& f : c.flags) {
    if (f == name) return true;
  }
  return false;
}

// Parses argv[2..] into flags (set through gflags) and positional arguments.
// Returns false after printing a usage error.
bool ParseFlags(const Command& c,
                int argc,
                char** argv,
                std::vector<std::string>* positional,
                bool* help) {
  for (int i = 2; i < argc; ++i) {
    std::string arg = argv[i];
    if (arg == "--") {
      for (++i; i < argc; ++i) positional->push_back(argv[i]);
      break;
    }
    if (arg.size() < 2 || arg[0] != '-' || arg == "-") {
      positional->push_back(arg);
      continue;
    }
    std::string body = arg.substr(arg[1] == '-' ? 2 : 1);
    if (body == "help" || body == "h") {
      *help = true;
      continue;
    }
    std::string name = body, value;
    bool has_value = false;
    const auto eq = body.find('=');
    if (eq != std::string::npos) {
      name = body.substr(0, eq);
      value = body.substr(eq + 1);
      has_value = true;
    }
    if (c.estimator_flags && FindEstimatorFlag(name) != nullptr) {
      const OptionSpec& spec = FindEstimatorFlag(name)->spec;
      if (!has_value) {
        if (spec.type == OptionType::kBool) {
          value = "true";
        } else if (i + 1 < argc) {
          value = argv[++i];
        } else {
          UsageError(c.name, "flag '--" + name + "' needs a value");
          return false;
        }
      }
      Status set = SetEstimatorFlag(name, value);
      if (!set.ok()) {
        UsageError(c.name,
                   "bad value '" + value + "' for flag '--" + name +
                       "' (expected " + OptionTypeToString(spec.type) + ")");
        return false;
      }
      MarkFlagSet(name);
      continue;
    }
    gflags::CommandLineFlagInfo info;
    bool known =
        Accepts(c, name) && gflags::GetCommandLineFlagInfo(name.c_str(), &info);
    if (!known && !has_value && name.rfind("no", 0) == 0 &&
        Accepts(c, name.substr(2)) &&
        gflags::GetCommandLineFlagInfo(name.substr(2).c_str(), &info) &&
        info.type == "bool") {
      name = name.substr(2);
      value = "false";
      has_value = true;
      known = true;
    }
    if (!known) {
      UsageError(c.name, "unknown flag '--" + name + "' for this command");
      return false;
    }
    if (!has_value) {
      if (info.type == "bool") {
        value = "true";
      } else if (i + 1 < argc) {
        value = argv[++i];
      } else {
        UsageError(c.name, "flag '--" + name + "' needs a value");
        return false;
      }
    }
    if (gflags::SetCommandLineOption(name.c_str(), value.c_str()).empty()) {
      UsageError(c.name,
                 "bad value '" + value + "' for flag '--" + name +
                     "' (expected " + info.type + ")");
      return false;
    }
    // Unset number flags default to NaN, so gflags accepts "nan" and "inf";
    // given explicitly they are never meant.
    if (info.type == "double") {
      gflags::CommandLineFlagInfo now;
      gflags::GetCommandLineFlagInfo(name.c_str(), &now);
      if (!std::isfinite(std::strtod(now.current_value.c_str(), nullptr))) {
        UsageError(
            c.name,
            "--" + name + "=" + value + ": the value must be a finite number");
        return false;
      }
    }
    MarkFlagSet(name);
    RecordFlagValue(name, value);
  }
  return true;
}

// No exception leaves a command: the library reports errors as Status, so
// anything thrown is either input that broke a third-party parser (a JSON
// value of the wrong type: the user's input, exit 2) or a resource failure
// (memory: exit 1). Either way the user gets one line, not an abort.
int RunBehindBarrier(const Command& c,
                     const std::vector<std::string>& positional) {
  try {
    return c.run(positional);
  } catch (const nlohmann::json::exception& e) {
    std::cerr << "imusysid " << c.name
              << ": error: bad JSON input: " << EscapeForDisplay(e.what())
              << "\n";
    return kExitBadInput;
  } catch (const std::bad_alloc&) {
    std::cerr << "imusysid " << c.name
              << ": error: out of memory (is an input or a flag far larger "
                 "than intended?)\n";
    return kExitInternal;
  } catch (const std::exception& e) {
    std::cerr << "imusysid " << c.name << ": error: internal: " << e.what()
              << "\n";
    return kExitInternal;
  } catch (...) {
    std::cerr << "imusysid " << c.name
              << ": error: internal: an unknown exception\n";
    return kExitInternal;
  }
}

int Main(int argc, char** argv) {
  if (argc < 2) {
    PrintToolHelp();
    return kExitBadInput;
  }
  const std::string name = argv[1];
  if (name == "--help" || name == "-h" || name == "help") {
    PrintToolHelp();
    return kExitOk;
  }
  if (name == "--version" || name == "version") {
    std::cout << "imusysid " IMUSYSID_VERSION_STRING "\n";
    return kExitOk;
  }
  for (const Command* c : AllCommands()) {
    if (c->name != name) continue;
    std::vector<std::string> positional;
    bool help = false;
    if (!ParseFlags(*c, argc, argv, &positional, &help)) return kExitBadInput;
    if (help) {
      PrintCommandHelp(*c);
      return kExitOk;
    }
    if (Accepts(*c, "format") && FLAGS_format != "table" &&
        FLAGS_format != "json") {
      return UsageError(
          c->name,
          "--format must be 'table' or 'json', not '" + FLAGS_format + "'");
    }
    return RunBehindBarrier(*c, positional);
  }
#ifndef IMUSYSID_CLI_HAS_BENCH
  if (name == "bench") {
    std::cerr << "imusysid: this build has no bench command (configured "
                 "with IMUSYSID_BUILD_BENCHMARKS=OFF)\n";
    return kExitBadInput;
  }
#endif
  std::cerr << "imusysid: unknown command '" << EscapeForDisplay(name) << "'\n";
  PrintToolHelp();
  return kExitBadInput;
}

}  // namespace
}  // namespace cli
}  // namespace imusysid

int main(int argc, char** argv) {
  FLAGS_logtostderr = true;
  FLAGS_minloglevel = 1;  // warnings and errors only; --v for more
  google::InitGoogleLogging(argv[0]);
  return imusysid::cli::Main(argc, argv);
}
