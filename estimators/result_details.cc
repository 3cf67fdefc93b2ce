// ResultDetails: the typed details of a result and their one formatter.

#include "imusysid/result.h"
#include "src/tools/format.h"

namespace imusysid {

void ResultDetails::Set(const std::string& key, Value value) {
  for (Entry& entry : entries_) {
    if (entry.first == key) {
      entry.second = std::move(value);
      return;
    }
  }
  entries_.emplace_back(key, std::move(value));
}

const ResultDetails::Value* ResultDetails::Find(std::string_view key) const {
  for (const Entry& entry : entries_) {
    if (entry.first == key) return &entry.second;
  }
  return nullptr;
}

std::optional<double> ResultDetails::Number(std::string_view key) const {
  const Value* v = Find(key);
  if (v == nullptr) return std::nullopt;
  if (const double* d = std::get_if<double>(v)) return *d;
  if (const std::int64_t* i = std::get_if<std::int64_t>(v)) {
    return static_cast<double>(*i);
  }
  return std::nullopt;
}

std::optional<std::int64_t> ResultDetails::Integer(std::string_view key) const {
  const Value* v = Find(key);
  if (v == nullptr) return std::nullopt;
  if (const std::int64_t* i = std::get_if<std::int64_t>(v)) return *i;
  return std::nullopt;
}

std::optional<std::string> ResultDetails::Text(std::string_view key) const {
  const Value* v = Find(key);
  if (v == nullptr) return std::nullopt;
  if (const std::string* s = std::get_if<std::string>(v)) return *s;
  return std::nullopt;
}

std::string ResultDetails::Format(std::string_view key) const {
  const Value* v = Find(key);
  return v == nullptr ? std::string() : FormatDetail(*v);
}

std::string FormatDetail(const ResultDetails::Value& value) {
  if (const std::int64_t* i = std::get_if<std::int64_t>(&value)) {
    return std::to_string(*i);
  }
  if (const double* d = std::get_if<double>(&value)) return FormatShortest(*d);
  return std::get<std::string>(value);
}

}  // namespace imusysid
