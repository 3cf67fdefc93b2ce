// The ULog parser's definitions: formats, info, parameters and
// subscriptions (ulog_parser.h).

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
#include "src/io/ulog_parser.h"
#include "src/tools/format.h"

namespace imusysid {
namespace ulog_internal {

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

}  // namespace ulog_internal
}  // namespace imusysid
