#include <map>
#include <string>
#include <string_view>
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
  return ParseLogParameters(*bytes, path);
}

StatusOr<std::vector<std::pair<std::string, double>>> ParseLogParameters(
    std::string_view bytes, const std::string& source) {
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
  switch (DetectLogFormat(bytes)) {
    case LogFormat::kUlog: {
      // Only the definitions and parameter messages are needed: decode no
      // topic.
      UlogReadOptions options;
      options.topics = {"-"};
      StatusOr<UlogData> ulog = ParseUlog(bytes, source, options);
      if (!ulog.ok()) return ulog.status();
      for (const UlogParameter& p : ulog->parameters) set(p.name, p.value);
      for (const UlogParameter& p : ulog->parameter_changes) {
        set(p.name, p.value);
      }
      break;
    }
    case LogFormat::kDataFlash: {
      // Only PARM: decode no other message's fields.
      DataFlashReadOptions options;
      options.messages = {"PARM"};
      StatusOr<DataFlashLog> log = ParseDataFlash(bytes, source, options);
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
