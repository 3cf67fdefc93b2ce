#include <map>
#include <string>
#include <utility>
#include <vector>

#include "imusysid/dataflash.h"
#include "imusysid/log.h"
#include "imusysid/log_reader.h"
#include "imusysid/ulog.h"

namespace imusysid {

StatusOr<std::vector<std::pair<std::string, double>>> ReadLogParameters(
    const std::string& path) {
  StatusOr<std::string> bytes = ReadFileToString(path);
  if (!bytes.ok()) return bytes.status();
  // The value in force at the end of the log: a ULog's initial values with
  // its in-flight changes applied, a DataFlash log's last PARM per name.
  std::map<std::string, double> values;
  std::vector<std::string> order;
  auto set = [&](const std::string& name, double value) {
    if (values.emplace(name, value).second) {
      order.push_back(name);
    } else {
      values[name] = value;
    }
  };
  switch (DetectLogFormat(*bytes)) {
    case LogFormat::kUlog: {
      // Only the definitions and parameter messages are needed: decode no
      // topic.
      UlogReadOptions options;
      options.topics = {"-"};
      StatusOr<UlogData> ulog = ParseUlog(*bytes, path, options);
      if (!ulog.ok()) return ulog.status();
      for (const UlogParameter& p : ulog->parameters) set(p.name, p.value);
      for (const UlogParameter& p : ulog->parameter_changes) {
        set(p.name, p.value);
      }
      break;
    }
    case LogFormat::kDataFlash: {
      StatusOr<DataFlashLog> log = ParseDataFlash(*bytes, path);
      if (!log.ok()) return log.status();
      for (const auto& [name, value] : log->parameters) set(name, value);
      break;
    }
    case LogFormat::kCsv:
      break;  // a CSV records no autopilot parameters
  }
  std::vector<std::pair<std::string, double>> out;
  out.reserve(order.size());
  for (const std::string& name : order) out.emplace_back(name, values[name]);
  return out;
}

}  // namespace imusysid
