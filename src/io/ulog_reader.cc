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

}  // namespace ulog_internal

using ulog_internal::kMagic;
using ulog_internal::Parser;

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
