#include <algorithm>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <map>
#include <memory>
#include <sstream>
#include <unordered_map>
#include <utility>

#include "imusysid/log.h"
#include "imusysid/ulog.h"
#include "src/tools/format.h"

namespace imusysid {
namespace {

constexpr unsigned char kMagic[7] = {0x55, 0x4C, 0x6F, 0x67, 0x01, 0x12, 0x35};
constexpr unsigned char kSyncMagic[8] = {
    0x2F, 0x73, 0x13, 0x20, 0x25, 0x0C, 0xBB, 0x12};
constexpr std::size_t kHeaderSize = 16;
constexpr std::size_t kMsgHeaderSize = 3;
// A D payload is at most 65535 bytes, so no useful format is larger; the limit
// also bounds the flattened field table of hostile nested arrays.
constexpr std::size_t kMaxFormatSize = 65535;
// Deepest nesting of formats accepted (PX4 uses 2-3 levels); also bounds the
// recursion depth on hostile input.
constexpr int kMaxNesting = 32;
// Totals over all subscriptions of flattened fields and of their names'
// characters. Real logs have a few tens of thousands of fields; the caps bound
// memory and time when hostile formats nest long names in large arrays.
constexpr std::size_t kMaxTotalFields = std::size_t{1} << 20;
constexpr std::size_t kMaxFieldNameChars = std::size_t{1} << 24;
// Bits of incompat_flags[0] this reader understands (DATA_APPENDED).
constexpr std::uint8_t kIncompatDataAppended = 0x01;

enum class BasicType : std::uint8_t {
  kInt8,
  kUint8,
  kInt16,
  kUint16,
  kInt32,
  kUint32,
  kInt64,
  kUint64,
  kFloat,
  kDouble,
  kBool,
  kChar,
};

struct BasicTypeInfo {
  const char* name;
  BasicType type;
  std::size_t size;
};

constexpr BasicTypeInfo kBasicTypes[] = {
    {"int8_t", BasicType::kInt8, 1},
    {"uint8_t", BasicType::kUint8, 1},
    {"int16_t", BasicType::kInt16, 2},
    {"uint16_t", BasicType::kUint16, 2},
    {"int32_t", BasicType::kInt32, 4},
    {"uint32_t", BasicType::kUint32, 4},
    {"int64_t", BasicType::kInt64, 8},
    {"uint64_t", BasicType::kUint64, 8},
    {"float", BasicType::kFloat, 4},
    {"double", BasicType::kDouble, 8},
    {"bool", BasicType::kBool, 1},
    {"char", BasicType::kChar, 1},
};

const BasicTypeInfo* FindBasicType(std::string_view name) {
  for (const BasicTypeInfo& info : kBasicTypes) {
    if (name == info.name) return &info;
  }
  return nullptr;
}

template <typename T>
T Load(const unsigned char* p) {
  T value;
  std::memcpy(&value, p, sizeof(T));
  return value;
}

double DecodeBasic(BasicType type, const unsigned char* p) {
  switch (type) {
    case BasicType::kInt8:
      return Load<std::int8_t>(p);
    case BasicType::kUint8:
    case BasicType::kBool:
    case BasicType::kChar:
      return *p;
    case BasicType::kInt16:
      return Load<std::int16_t>(p);
    case BasicType::kUint16:
      return Load<std::uint16_t>(p);
    case BasicType::kInt32:
      return Load<std::int32_t>(p);
    case BasicType::kUint32:
      return Load<std::uint32_t>(p);
    case BasicType::kInt64:
      return static_cast<double>(Load<std::int64_t>(p));
    case BasicType::kUint64:
      return static_cast<double>(Load<std::uint64_t>(p));
    case BasicType::kFloat:
      return Load<float>(p);
    case BasicType::kDouble:
      return Load<double>(p);
  }
  return 0;
}

// One field of an `F` message: `type name` or `type[array_len] name`.
struct FieldDef {
  std::string type;
  std::size_t array_len = 0;  // 0 = scalar
  std::string name;
};

struct FormatDef {
  std::vector<FieldDef> fields;
  std::uint64_t offset = 0;  // of the F message
};

// One decoded element of a flattened format.
struct FlatField {
  std::uint32_t offset;
  BasicType type;
};

struct Subscription {
  std::size_t topic_index;
  std::vector<FlatField> fields;  // column k = fields[k]
  std::size_t logged_size;        // S_logged
  std::size_t full_size;          // S_full
  int timestamp_field = -1;       // index into fields, uint64 `timestamp`
  bool decode = true;
};

class Parser {
 public:
  Parser(std::string_view bytes,
         const std::string& name,
         const UlogReadOptions& options)
      : data_(reinterpret_cast<const unsigned char*>(bytes.data())),
        size_(bytes.size()),
        name_(name),
        options_(options) {}

  StatusOr<UlogData> Parse();

 private:
  enum class Outcome { kOk, kCorrupt };

  Status Error(std::uint64_t offset, const std::string& what) const {
    return InvalidArgumentError(name_ + ": byte " + std::to_string(offset) +
                                ": " + what);
  }
  void Warn(std::uint64_t offset, const std::string& what) {
    if (out_.warnings.size() < kMaxUlogWarnings) {
      out_.warnings.push_back("byte " + std::to_string(offset) + ": " + what);
    } else if (out_.warnings.size() == kMaxUlogWarnings) {
      out_.warnings.push_back("... more warnings not shown");
    }
  }

  // Parses messages in [begin, end); `end` < size_ marks an appended-data
  // boundary where a message crossing it is incomplete.
  Status ParseSegment(std::size_t begin, std::size_t end);
  // Fills data_counts_ by walking message headers from `begin` until the
  // first implausible one.
  void PrescanDataCounts(std::size_t begin);
  // Scans [from, end) for the sync magic; returns the offset just after it
  // or `end` when there is none.
  std::size_t Resync(std::size_t corrupt_at, std::size_t from, std::size_t end);

  Status HandleFlagBits(std::size_t pos, const unsigned char* p, std::size_t n);
  Status HandleFormat(std::size_t pos, const unsigned char* p, std::size_t n);
  Outcome HandleInfo(std::size_t pos, const unsigned char* p, std::size_t n);
  Outcome HandleMultiInfo(std::size_t pos,
                          const unsigned char* p,
                          std::size_t n);
  Outcome HandleParameter(std::size_t pos,
                          const unsigned char* p,
                          std::size_t n,
                          bool is_default);
  Status HandleSubscription(std::size_t pos,
                            const unsigned char* p,
                            std::size_t n,
                            Outcome* outcome);
  Outcome HandleData(std::size_t pos, const unsigned char* p, std::size_t n);

  // Size of format/basic type `type`, recursively; errors name `offset`.
  Status TypeSize(const std::string& type,
                  std::uint64_t offset,
                  int depth,
                  std::size_t* size);
  Status Flatten(const std::string& format,
                 const std::string& prefix,
                 std::size_t base,
                 std::uint64_t offset,
                 int depth,
                 std::vector<FlatField>* fields,
                 std::vector<std::string>* names);

  const unsigned char* data_;
  std::size_t size_;
  const std::string& name_;
  const UlogReadOptions& options_;
  UlogData out_;
  bool in_data_section_ = false;
  std::size_t name_chars_ = 0;    // over all subscriptions
  std::size_t total_fields_ = 0;  // over all subscriptions
  std::unordered_map<std::string, FormatDef> formats_;
  // Key → index into out_.info / parameters / multi_info (keys are unique).
  std::unordered_map<std::string, std::size_t> info_index_;
  std::unordered_map<std::string, std::size_t> parameter_index_;
  std::unordered_map<std::string, std::size_t> multi_info_index_;
  // "name\0multi_id" → indices into out_.topics (usually one).
  std::unordered_map<std::string, std::vector<std::size_t>> topic_index_;
  std::unordered_map<std::string, std::size_t> size_cache_;
  std::vector<Subscription> subscriptions_;
  // msg_id → index into subscriptions_, -1 when none; grown on demand (ids
  // are assigned from 0 upwards, so this stays small).
  std::vector<int> subscriptions_by_id_;
  // D messages per msg_id from a quick header walk, to size the columns once
  // (growing thousands of vectors sample by sample dominated the run time).
  std::vector<std::uint32_t> data_counts_;
  // Doubles still allowed to be reserved: decoded values never exceed the
  // file's byte count, so reserving more than that is never needed.
  std::size_t reserve_budget_ = 0;
};

Status Parser::TypeSize(const std::string& type,
                        std::uint64_t offset,
                        int depth,
                        std::size_t* size) {
  if (const BasicTypeInfo* basic = FindBasicType(type)) {
    *size = basic->size;
    return Status::Ok();
  }
  auto cached = size_cache_.find(type);
  if (cached != size_cache_.end()) {
    *size = cached->second;
    return Status::Ok();
  }
  if (depth > kMaxNesting) {
    return Error(offset,
                 "format '" + type +
                     "' is recursive or nested deeper "
                     "than " +
                     std::to_string(kMaxNesting) + " levels");
  }
  auto it = formats_.find(type);
  if (it == formats_.end()) {
    return Error(offset, "undefined type '" + type + "'");
  }
  std::size_t total = 0;
  for (const FieldDef& field : it->second.fields) {
    std::size_t element = 0;
    IMUSYSID_RETURN_IF_ERROR(TypeSize(field.type, offset, depth + 1, &element));
    const std::size_t count = field.array_len == 0 ? 1 : field.array_len;
    if (element > kMaxFormatSize || count > kMaxFormatSize ||
        element * count > kMaxFormatSize) {
      return Error(offset,
                   "format '" + type + "' field '" + field.name +
                       "' is larger than " + std::to_string(kMaxFormatSize) +
                       " bytes");
    }
    total += element * count;
    if (total > kMaxFormatSize) {
      return Error(offset,
                   "format '" + type + "' is larger than " +
                       std::to_string(kMaxFormatSize) + " bytes");
    }
  }
  if (total == 0) {
    return Error(offset, "format '" + type + "' has no fields");
  }
  size_cache_[type] = total;
  *size = total;
  return Status::Ok();
}

Status Parser::Flatten(const std::string& format,
                       const std::string& prefix,
                       std::size_t base,
                       std::uint64_t offset,
                       int depth,
                       std::vector<FlatField>* fields,
                       std::vector<std::string>* names) {
  const FormatDef& def = formats_.at(format);  // TypeSize checked it exists
  std::size_t pos = base;
  for (const FieldDef& field : def.fields) {
    std::size_t element = 0;
    IMUSYSID_RETURN_IF_ERROR(TypeSize(field.type, offset, depth + 1, &element));
    const std::size_t count = field.array_len == 0 ? 1 : field.array_len;
    const bool padding = field.name.rfind("_padding", 0) == 0;
    if (!padding) {
      const BasicTypeInfo* basic = FindBasicType(field.type);
      for (std::size_t i = 0; i < count; ++i) {
        std::string child = prefix + field.name;
        if (field.array_len != 0) child += "[" + std::to_string(i) + "]";
        const std::size_t at = pos + i * element;
        if (basic != nullptr) {
          name_chars_ += child.size();
          if (name_chars_ > kMaxFieldNameChars ||
              ++total_fields_ > kMaxTotalFields) {
            return Error(offset,
                         "subscriptions flatten to more than " +
                             std::to_string(kMaxTotalFields) +
                             " fields or too long field names");
          }
          fields->push_back({static_cast<std::uint32_t>(at), basic->type});
          names->push_back(std::move(child));
        } else {
          IMUSYSID_RETURN_IF_ERROR(Flatten(
              field.type, child + ".", at, offset, depth + 1, fields, names));
        }
      }
    }
    pos += element * count;
  }
  return Status::Ok();
}

std::size_t Parser::Resync(std::size_t corrupt_at,
                           std::size_t from,
                           std::size_t end) {
  ++out_.stats.resyncs;
  const unsigned char* begin = data_ + std::min(from, end);
  const unsigned char* found = std::search(
      begin, data_ + end, std::begin(kSyncMagic), std::end(kSyncMagic));
  const std::size_t next =
      found == data_ + end ? end : (found - data_) + sizeof(kSyncMagic);
  out_.stats.skipped_bytes += next - corrupt_at;
  Warn(corrupt_at,
       next == end ? "corrupt message header; no sync magic follows, " +
                         std::to_string(end - corrupt_at) + " bytes skipped"
                   : "corrupt message header; resynchronised at byte " +
                         std::to_string(next));
  return next;
}

Status Parser::HandleFlagBits(std::size_t pos,
                              const unsigned char* p,
                              std::size_t n) {
  if (pos != kHeaderSize) {
    Warn(pos, "flag bits message not at byte 16 ignored");
    return Status::Ok();
  }
  if (n < 40) {
    return Error(pos,
                 "flag bits message has " + std::to_string(n) +
                     " payload bytes, needs 40");
  }
  out_.has_flag_bits = true;
  std::memcpy(out_.compat_flags, p, 8);
  std::memcpy(out_.incompat_flags, p + 8, 8);
  for (int i = 0; i < 8; ++i) {
    const std::uint8_t known = i == 0 ? kIncompatDataAppended : 0;
    const std::uint8_t unknown = out_.incompat_flags[i] & ~known;
    if (unknown != 0) {
      char hex[8];
      std::snprintf(hex, sizeof(hex), "0x%02x", unknown);
      return Error(pos,
                   "unknown incompat_flags[" + std::to_string(i) + "] bits " +
                       hex +
                       ": the log uses a feature this reader does not "
                       "understand");
    }
  }
  if ((out_.incompat_flags[0] & kIncompatDataAppended) != 0) {
    for (int i = 0; i < 3; ++i) {
      const auto offset = Load<std::uint64_t>(p + 16 + 8 * i);
      if (offset != 0) out_.appended_offsets.push_back(offset);
    }
  }
  return Status::Ok();
}

bool IsNameChar(char c, bool allow_slash) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
         (c >= '0' && c <= '9') || c == '_' ||
         (allow_slash && (c == '-' || c == '/'));
}

Status Parser::HandleFormat(std::size_t pos,
                            const unsigned char* p,
                            std::size_t n) {
  const std::string_view text(reinterpret_cast<const char*>(p), n);
  const std::size_t colon = text.find(':');
  if (colon == std::string_view::npos || colon == 0) {
    return Error(pos, "format definition without 'name:' prefix");
  }
  std::string format_name(text.substr(0, colon));
  for (char c : format_name) {
    if (!IsNameChar(c, true)) {
      return Error(
          pos, "format name '" + format_name + "' has an invalid character");
    }
  }
  FormatDef def;
  def.offset = pos;
  std::string_view rest = text.substr(colon + 1);
  while (!rest.empty()) {
    const std::size_t semi = rest.find(';');
    std::string_view item = rest.substr(0, semi);
    rest = semi == std::string_view::npos ? std::string_view()
                                          : rest.substr(semi + 1);
    // Tolerate trailing NULs and empty items (";;", final ';').
    while (!item.empty() && (item.back() == '\0' || item.back() == ' ')) {
      item.remove_suffix(1);
    }
    if (item.empty()) continue;
    const std::size_t space = item.find(' ');
    if (space == std::string_view::npos) {
      return Error(pos,
                   "format '" + format_name + "' field '" + std::string(item) +
                       "' is not 'type name'");
    }
    FieldDef field;
    std::string_view type = item.substr(0, space);
    field.name = std::string(item.substr(space + 1));
    if (field.name.empty()) {
      return Error(pos,
                   "format '" + format_name + "' has a field without name");
    }
    const std::size_t bracket = type.find('[');
    if (bracket != std::string_view::npos) {
      if (type.back() != ']' || bracket + 2 >= type.size()) {
        return Error(pos,
                     "format '" + format_name + "' field '" + field.name +
                         "' has a malformed array type '" + std::string(type) +
                         "'");
      }
      std::size_t len = 0;
      for (std::size_t i = bracket + 1; i + 1 < type.size(); ++i) {
        const char c = type[i];
        if (c < '0' || c > '9' || len > kMaxFormatSize) {
          return Error(pos,
                       "format '" + format_name + "' field '" + field.name +
                           "' has a bad array length in '" + std::string(type) +
                           "'");
        }
        len = len * 10 + static_cast<std::size_t>(c - '0');
      }
      if (len == 0 || len > kMaxFormatSize) {
        return Error(pos,
                     "format '" + format_name + "' field '" + field.name +
                         "' has array length " + std::to_string(len) +
                         " (allowed 1.." + std::to_string(kMaxFormatSize) +
                         ")");
      }
      field.array_len = len;
      type = type.substr(0, bracket);
    }
    field.type = std::string(type);
    def.fields.push_back(std::move(field));
  }
  if (formats_.count(format_name) != 0) {
    Warn(pos,
         "format '" + format_name +
             "' redefined; the new one is used by "
             "later subscriptions");
  }
  formats_[format_name] = std::move(def);
  size_cache_.clear();
  return Status::Ok();
}

// Splits "type name" keys; returns false when there is no space.
bool SplitKey(std::string_view key, std::string* type, std::string* name) {
  const std::size_t space = key.find(' ');
  if (space == std::string_view::npos) return false;
  *type = std::string(key.substr(0, space));
  *name = std::string(key.substr(space + 1));
  return true;
}

// Renders an I/P value of declared type `type` (e.g. "char[40]", "float").
std::string RenderValue(const std::string& type, std::string_view raw) {
  std::string base = type;
  const std::size_t bracket = base.find('[');
  if (bracket != std::string::npos) base = base.substr(0, bracket);
  if (base == "char") {
    std::string text(raw);
    const std::size_t nul = text.find('\0');
    if (nul != std::string::npos) text.resize(nul);
    return text;
  }
  const BasicTypeInfo* info = FindBasicType(base);
  if (info == nullptr || raw.size() % info->size != 0 || raw.empty()) {
    return std::string(raw);
  }
  std::string out;
  for (std::size_t i = 0; i < raw.size(); i += info->size) {
    if (!out.empty()) out += ",";
    const double v = DecodeBasic(
        info->type, reinterpret_cast<const unsigned char*>(raw.data() + i));
    if (info->type == BasicType::kUint64) {
      out += std::to_string(Load<std::uint64_t>(
          reinterpret_cast<const unsigned char*>(raw.data() + i)));
    } else if (info->type == BasicType::kInt64) {
      out += std::to_string(Load<std::int64_t>(
          reinterpret_cast<const unsigned char*>(raw.data() + i)));
    } else {
      out += FormatNumber(v, 9, NonFiniteStyle::kPrintf);
    }
  }
  return out;
}

Parser::Outcome Parser::HandleInfo(std::size_t pos,
                                   const unsigned char* p,
                                   std::size_t n) {
  const std::size_t key_len = p[0];
  if (1 + key_len > n) return Outcome::kCorrupt;
  UlogInfo info;
  if (!SplitKey(std::string_view(reinterpret_cast<const char*>(p + 1), key_len),
                &info.type,
                &info.key)) {
    Warn(pos, "information key without type ignored");
    return Outcome::kOk;
  }
  info.value = RenderValue(
      info.type,
      std::string_view(reinterpret_cast<const char*>(p + 1 + key_len),
                       n - 1 - key_len));
  auto [it, added] = info_index_.emplace(info.key, out_.info.size());
  if (added) {
    out_.info.push_back(std::move(info));
  } else {
    out_.info[it->second] = std::move(info);
  }
  return Outcome::kOk;
}

Parser::Outcome Parser::HandleMultiInfo(std::size_t pos,
                                        const unsigned char* p,
                                        std::size_t n) {
  if (n < 2) return Outcome::kCorrupt;
  const bool continued = p[0] != 0;
  const std::size_t key_len = p[1];
  if (2 + key_len > n) return Outcome::kCorrupt;
  std::string type, key;
  if (!SplitKey(std::string_view(reinterpret_cast<const char*>(p + 2), key_len),
                &type,
                &key)) {
    Warn(pos, "multi-information key without type ignored");
    return Outcome::kOk;
  }
  std::string value(reinterpret_cast<const char*>(p + 2 + key_len),
                    n - 2 - key_len);
  auto [it, added] = multi_info_index_.emplace(key, out_.multi_info.size());
  if (added) out_.multi_info.push_back({key, type, {}});
  UlogMultiInfo* entry = &out_.multi_info[it->second];
  if (continued && !entry->values.empty()) {
    entry->values.back() += value;
  } else {
    entry->values.push_back(std::move(value));
  }
  return Outcome::kOk;
}

Parser::Outcome Parser::HandleParameter(std::size_t pos,
                                        const unsigned char* p,
                                        std::size_t n,
                                        bool is_default) {
  const std::size_t head = is_default ? 2 : 1;
  if (n < head) return Outcome::kCorrupt;
  const std::size_t key_len = p[head - 1];
  if (head + key_len > n) return Outcome::kCorrupt;
  std::string type;
  UlogParameter param;
  param.offset = pos;
  param.default_types = is_default ? p[0] : 0;
  if (!SplitKey(
          std::string_view(reinterpret_cast<const char*>(p + head), key_len),
          &type,
          &param.name)) {
    Warn(pos, "parameter key without type ignored");
    return Outcome::kOk;
  }
  const unsigned char* value = p + head + key_len;
  const std::size_t value_len = n - head - key_len;
  if (type == "int32_t" && value_len == 4) {
    param.value = Load<std::int32_t>(value);
  } else if (type == "float" && value_len == 4) {
    param.value = Load<float>(value);
  } else {
    Warn(pos,
         "parameter '" + param.name + "' of type '" + type + "' with " +
             std::to_string(value_len) + " value bytes ignored");
    return Outcome::kOk;
  }
  if (is_default) {
    out_.default_parameters.push_back(std::move(param));
  } else if (in_data_section_) {
    out_.parameter_changes.push_back(std::move(param));
  } else {
    auto [it, added] =
        parameter_index_.emplace(param.name, out_.parameters.size());
    if (added) {
      out_.parameters.push_back(std::move(param));
    } else {
      out_.parameters[it->second] = std::move(param);
    }
  }
  return Outcome::kOk;
}

Status Parser::HandleSubscription(std::size_t pos,
                                  const unsigned char* p,
                                  std::size_t n,
                                  Outcome* outcome) {
  *outcome = Outcome::kOk;
  if (n < 4) {
    *outcome = Outcome::kCorrupt;
    return Status::Ok();
  }
  const int multi_id = p[0];
  const std::uint16_t msg_id = Load<std::uint16_t>(p + 1);
  std::string topic(reinterpret_cast<const char*>(p + 3), n - 3);
  while (!topic.empty() && topic.back() == '\0') topic.pop_back();
  if (formats_.count(topic) == 0) {
    return Error(pos,
                 "subscription msg_id " + std::to_string(msg_id) +
                     " refers to undefined format '" + topic + "'");
  }
  Subscription sub;
  std::vector<std::string> names;
  IMUSYSID_RETURN_IF_ERROR(TypeSize(topic, pos, 0, &sub.full_size));
  IMUSYSID_RETURN_IF_ERROR(Flatten(topic, "", 0, pos, 0, &sub.fields, &names));
  // Trailing padding of the top-level struct is not written in D messages.
  std::size_t trailing = 0;
  const std::vector<FieldDef>& fields = formats_.at(topic).fields;
  for (auto it = fields.rbegin(); it != fields.rend(); ++it) {
    if (it->name.rfind("_padding", 0) != 0) break;
    std::size_t element = 0;
    IMUSYSID_RETURN_IF_ERROR(TypeSize(it->type, pos, 1, &element));
    trailing += element * (it->array_len == 0 ? 1 : it->array_len);
  }
  sub.logged_size = sub.full_size - trailing;
  for (std::size_t k = 0; k < names.size(); ++k) {
    if (names[k] == "timestamp" && sub.fields[k].type == BasicType::kUint64) {
      sub.timestamp_field = static_cast<int>(k);
      break;
    }
  }
  sub.decode =
      options_.topics.empty() ||
      std::find(options_.topics.begin(), options_.topics.end(), topic) !=
          options_.topics.end();
  // Reuse the topic entry for a repeated (name, multi_id) with the same layout.
  std::size_t index = out_.topics.size();
  std::vector<std::size_t>& same_name =
      topic_index_[topic + '\0' + std::to_string(multi_id)];
  for (std::size_t i : same_name) {
    if (out_.topics[i].field_names == names) index = i;
  }
  if (index == out_.topics.size()) same_name.push_back(index);
  if (index == out_.topics.size()) {
    UlogTopic entry;
    entry.name = topic;
    entry.multi_id = multi_id;
    entry.field_names = std::move(names);
    entry.columns.resize(entry.field_names.size());
    // Each D of this topic takes at least 5 + S_logged bytes of the rest.
    std::size_t expected = std::min<std::size_t>(
        msg_id < data_counts_.size() ? data_counts_[msg_id] : 0,
        (size_ - pos) / (5 + sub.logged_size));
    if (!sub.decode) expected = 0;
    const std::size_t doubles = expected * (entry.columns.size() + 2);
    if (doubles <= reserve_budget_) {
      reserve_budget_ -= doubles;
      for (std::vector<double>& column : entry.columns)
        column.reserve(expected);
      entry.timestamps_us.reserve(expected);
      entry.offsets.reserve(expected);
    }
    out_.topics.push_back(std::move(entry));
  }
  sub.topic_index = index;
  if (msg_id >= subscriptions_by_id_.size()) {
    subscriptions_by_id_.resize(std::size_t{msg_id} + 1, -1);
  } else if (subscriptions_by_id_[msg_id] >= 0) {
    Warn(pos,
         "msg_id " + std::to_string(msg_id) +
             " subscribed again; later data goes to '" + topic + "'");
  }
  subscriptions_by_id_[msg_id] = static_cast<int>(subscriptions_.size());
  subscriptions_.push_back(std::move(sub));
  return Status::Ok();
}

Parser::Outcome Parser::HandleData(std::size_t pos,
                                   const unsigned char* p,
                                   std::size_t n) {
  if (n < 2) return Outcome::kCorrupt;
  const std::uint16_t msg_id = Load<std::uint16_t>(p);
  const int index =
      msg_id < subscriptions_by_id_.size() ? subscriptions_by_id_[msg_id] : -1;
  if (index < 0) {
    if (out_.stats.unknown_msg_id++ == 0) {
      Warn(pos,
           "data for unsubscribed msg_id " + std::to_string(msg_id) +
               " skipped (further ones only counted)");
    }
    return Outcome::kOk;
  }
  const Subscription& sub = subscriptions_[static_cast<std::size_t>(index)];
  const std::size_t payload = n - 2;
  if (payload < sub.logged_size || payload > sub.full_size) {
    ++out_.stats.bad_data_size;
    Warn(pos,
         "data for '" + out_.topics[sub.topic_index].name + "' has " +
             std::to_string(payload) + " bytes, expected " +
             std::to_string(sub.logged_size) +
             (sub.full_size != sub.logged_size
                  ? " or " + std::to_string(sub.full_size)
                  : std::string()));
    return Outcome::kCorrupt;
  }
  if (!sub.decode) {
    ++out_.stats.skipped_topic_samples;
    return Outcome::kOk;
  }
  UlogTopic& topic = out_.topics[sub.topic_index];
  const unsigned char* body = p + 2;
  const std::size_t count = sub.fields.size();
  std::vector<double>* columns = topic.columns.data();
  for (std::size_t k = 0; k < count; ++k) {
    const FlatField& field = sub.fields[k];
    const unsigned char* at = body + field.offset;
    double value;
    // The common types first and inline: this loop is the reader's hot path.
    switch (field.type) {
      case BasicType::kFloat:
        value = Load<float>(at);
        break;
      case BasicType::kUint64:
        value = static_cast<double>(Load<std::uint64_t>(at));
        break;
      case BasicType::kUint8:
      case BasicType::kBool:
      case BasicType::kChar:
        value = *at;
        break;
      case BasicType::kInt32:
        value = Load<std::int32_t>(at);
        break;
      case BasicType::kUint32:
        value = Load<std::uint32_t>(at);
        break;
      default:
        value = DecodeBasic(field.type, at);
        break;
    }
    columns[k].push_back(value);
  }
  if (sub.timestamp_field >= 0) {
    topic.timestamps_us.push_back(Load<std::uint64_t>(
        body +
        sub.fields[static_cast<std::size_t>(sub.timestamp_field)].offset));
  }
  topic.offsets.push_back(pos);
  return Outcome::kOk;
}

bool IsPlausibleType(unsigned char type) {
  return (type >= 'A' && type <= 'Z') || (type >= 'a' && type <= 'z');
}

Status Parser::ParseSegment(std::size_t begin, std::size_t end) {
  const bool appended_boundary = end < size_;
  std::size_t pos = begin;
  while (pos < end) {
    if (end - pos < kMsgHeaderSize) {
      if (appended_boundary) {
        ++out_.stats.dropped_at_boundary;
      } else {
        out_.stats.truncated_tail_bytes += end - pos;
        Warn(pos, "incomplete message header at end of file dropped");
      }
      return Status::Ok();
    }
    const std::size_t msg_size = Load<std::uint16_t>(data_ + pos);
    const unsigned char type = data_[pos + 2];
    if (msg_size == 0 || !IsPlausibleType(type)) {
      pos = Resync(pos, pos + 1, end);
      continue;
    }
    if (msg_size > end - pos - kMsgHeaderSize) {
      if (appended_boundary) {
        ++out_.stats.dropped_at_boundary;
        Warn(pos,
             "message crossing the appended-data offset " +
                 std::to_string(end) + " dropped");
        return Status::Ok();
      }
      // A bogus size in mid-file is corruption if a sync magic follows;
      // otherwise the log was cut off inside its last message.
      const unsigned char* found = std::search(data_ + pos + kMsgHeaderSize,
                                               data_ + end,
                                               std::begin(kSyncMagic),
                                               std::end(kSyncMagic));
      if (found != data_ + end) {
        pos = Resync(pos, pos + 1, end);
        continue;
      }
      out_.stats.truncated_tail_bytes += end - pos;
      Warn(pos,
           "truncated last message (type '" +
               std::string(1, static_cast<char>(type)) + "', " +
               std::to_string(msg_size) + " bytes) dropped");
      return Status::Ok();
    }
    ++out_.stats.messages;
    const unsigned char* payload = data_ + pos + kMsgHeaderSize;
    Outcome outcome = Outcome::kOk;
    switch (type) {
      case 'D':
        outcome = HandleData(pos, payload, msg_size);
        break;
      case 'B':
        IMUSYSID_RETURN_IF_ERROR(HandleFlagBits(pos, payload, msg_size));
        break;
      case 'F':
        IMUSYSID_RETURN_IF_ERROR(HandleFormat(pos, payload, msg_size));
        break;
      case 'I':
        outcome = HandleInfo(pos, payload, msg_size);
        break;
      case 'M':
        outcome = HandleMultiInfo(pos, payload, msg_size);
        break;
      case 'P':
        outcome = HandleParameter(pos, payload, msg_size, false);
        break;
      case 'Q':
        outcome = HandleParameter(pos, payload, msg_size, true);
        break;
      case 'A':
        in_data_section_ = true;
        IMUSYSID_RETURN_IF_ERROR(
            HandleSubscription(pos, payload, msg_size, &outcome));
        break;
      case 'R':
        if (msg_size != 2) {
          outcome = Outcome::kCorrupt;
        } else {
          const std::uint16_t id = Load<std::uint16_t>(payload);
          if (id < subscriptions_by_id_.size()) subscriptions_by_id_[id] = -1;
        }
        break;
      case 'L':
      case 'C': {
        in_data_section_ = true;
        const std::size_t head = type == 'L' ? 9 : 11;
        if (msg_size < head) {
          outcome = Outcome::kCorrupt;
          break;
        }
        UlogLoggedString s;
        s.level = payload[0] >= '0' && payload[0] <= '7' ? payload[0] - '0'
                                                         : payload[0];
        if (type == 'C') s.tag = Load<std::uint16_t>(payload + 1);
        s.timestamp_us = Load<std::uint64_t>(payload + head - 8);
        s.text.assign(reinterpret_cast<const char*>(payload + head),
                      msg_size - head);
        out_.logged_strings.push_back(std::move(s));
        break;
      }
      case 'S':
        if (msg_size != sizeof(kSyncMagic) ||
            std::memcmp(payload, kSyncMagic, sizeof(kSyncMagic)) != 0) {
          outcome = Outcome::kCorrupt;
        }
        break;
      case 'O':
        if (msg_size != 2) {
          outcome = Outcome::kCorrupt;
        } else {
          ++out_.dropout_count;
          out_.dropout_total_ms += Load<std::uint16_t>(payload);
        }
        break;
      default:
        if (out_.stats.unknown_types++ == 0) {
          Warn(pos,
               "unknown message type '" +
                   std::string(1, static_cast<char>(type)) +
                   "' skipped (further ones only counted)");
        }
        break;
    }
    if (outcome == Outcome::kCorrupt) {
      pos = Resync(pos, pos + 1, end);
      continue;
    }
    pos += kMsgHeaderSize + msg_size;
  }
  return Status::Ok();
}

void Parser::PrescanDataCounts(std::size_t begin) {
  data_counts_.clear();
  reserve_budget_ = size_;
  std::size_t pos = begin;
  while (size_ - pos >= kMsgHeaderSize + 2) {
    const std::size_t msg_size = Load<std::uint16_t>(data_ + pos);
    const unsigned char type = data_[pos + 2];
    if (msg_size == 0 || !IsPlausibleType(type) ||
        msg_size > size_ - pos - kMsgHeaderSize) {
      break;
    }
    if (type == 'D' && msg_size >= 2) {
      const std::uint16_t id =
          Load<std::uint16_t>(data_ + pos + kMsgHeaderSize);
      if (id >= data_counts_.size())
        data_counts_.resize(std::size_t{id} + 1, 0);
      ++data_counts_[id];
    }
    pos += kMsgHeaderSize + msg_size;
  }
}

StatusOr<UlogData> Parser::Parse() {
  if (size_ < kHeaderSize || std::memcmp(data_, kMagic, sizeof(kMagic)) != 0) {
    return Error(0,
                 size_ < kHeaderSize && size_ >= sizeof(kMagic) &&
                         std::memcmp(data_, kMagic, sizeof(kMagic)) == 0
                     ? "file shorter than the 16-byte ULog header"
                     : "not a ULog file (bad magic)");
  }
  out_.version = data_[7];
  out_.start_timestamp_us = Load<std::uint64_t>(data_ + 8);
  if (out_.version > 1) {
    Warn(7,
         "file format version " + std::to_string(out_.version) +
             " is newer than this reader knows (1); reading anyway");
  }
  // The B message decides the segments, so read it before the main loop.
  std::size_t pos = kHeaderSize;
  if (size_ - pos >= kMsgHeaderSize && data_[pos + 2] == 'B') {
    const std::size_t msg_size = Load<std::uint16_t>(data_ + pos);
    if (msg_size <= size_ - pos - kMsgHeaderSize) {
      IMUSYSID_RETURN_IF_ERROR(
          HandleFlagBits(pos, data_ + pos + kMsgHeaderSize, msg_size));
      ++out_.stats.messages;
      pos += kMsgHeaderSize + msg_size;
    }
  }
  PrescanDataCounts(pos);
  std::vector<std::size_t> boundaries;
  for (std::uint64_t offset : out_.appended_offsets) {
    const std::size_t last = boundaries.empty() ? pos : boundaries.back();
    if (offset <= last || offset > size_) {
      Warn(16,
           "appended-data offset " + std::to_string(offset) +
               " ignored (not after " + std::to_string(last) +
               " or past the end of the " + std::to_string(size_) +
               "-byte file)");
      continue;
    }
    boundaries.push_back(static_cast<std::size_t>(offset));
  }
  boundaries.push_back(size_);
  for (std::size_t end : boundaries) {
    IMUSYSID_RETURN_IF_ERROR(ParseSegment(pos, end));
    pos = end;
  }
  return std::move(out_);
}

}  // namespace

const std::vector<double>* UlogTopic::FindColumn(std::string_view field) const {
  for (std::size_t k = 0; k < field_names.size(); ++k) {
    if (field_names[k] == field) return &columns[k];
  }
  return nullptr;
}

const UlogTopic* UlogData::FindTopic(std::string_view name,
                                     int multi_id) const {
  for (const UlogTopic& topic : topics) {
    if (topic.name == name && topic.multi_id == multi_id) return &topic;
  }
  return nullptr;
}

const UlogInfo* UlogData::FindInfo(std::string_view key) const {
  for (const UlogInfo& entry : info) {
    if (entry.key == key) return &entry;
  }
  return nullptr;
}

const UlogMultiInfo* UlogData::FindMultiInfo(std::string_view key) const {
  for (const UlogMultiInfo& entry : multi_info) {
    if (entry.key == key) return &entry;
  }
  return nullptr;
}

std::optional<double> UlogData::FindParameter(std::string_view name) const {
  for (const UlogParameter& param : parameters) {
    if (param.name == name) return param.value;
  }
  return std::nullopt;
}

bool LooksLikeUlog(std::string_view bytes) {
  return bytes.size() >= sizeof(kMagic) &&
         std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) == 0;
}

StatusOr<UlogData> ParseUlog(std::string_view bytes,
                             const std::string& name,
                             const UlogReadOptions& options) {
  Parser parser(bytes, name, options);
  return parser.Parse();
}

StatusOr<UlogData> ReadUlog(const std::string& path,
                            const UlogReadOptions& options) {
  StatusOr<std::string> bytes = ReadFileToString(path);
  if (!bytes.ok()) return bytes.status();
  return ParseUlog(*bytes, path, options);
}

}  // namespace imusysid
