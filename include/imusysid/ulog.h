// Reader for PX4 ULog files (.ulg): decodes every message type of the format
// (shared/docs/ulog-format.md) into plain tables, with the spec's robustness
// rules (truncation, resynchronisation on the sync magic, appended data).

#ifndef IMUSYSID_ULOG_H_
#define IMUSYSID_ULOG_H_

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "imusysid/status.h"

namespace imusysid {

// The samples of one subscription (topic name, multi_id), column by column.
struct UlogTopic {
  std::string name;
  int multi_id = 0;
  // Flattened field names in struct order: "field", "field[i]",
  // "nested.child", "nested[i].child". `_padding*` fields are omitted.
  std::vector<std::string> field_names;
  // columns[k][i] is field_names[k] of sample i, converted to double (exact for
  // every integer up to 2^53, so µs timestamps stay exact).
  std::vector<std::vector<double>> columns;
  // The `timestamp` field (µs) exactly; empty when the format has none.
  std::vector<std::uint64_t> timestamps_us;
  // Byte offset of each sample's D message, for error messages.
  std::vector<std::uint64_t> offsets;

  std::size_t size() const { return offsets.size(); }
  // The column named `field`, or nullptr.
  const std::vector<double>* FindColumn(std::string_view field) const;
};

// An `I` message: `key` is the name, `type` the declared type ("char[40]").
// `value` is the text for char arrays, the decimal number for scalars, the
// comma-separated numbers for numeric arrays.
struct UlogInfo {
  std::string key;
  std::string type;
  std::string value;
};

// An `M` key with all its values in file order (continuations concatenated).
// Values are raw bytes (usually text).
struct UlogMultiInfo {
  std::string key;
  std::string type;
  std::vector<std::string> values;
};

// A `P` (or `Q`) message. `default_types` is the Q bitfield (0 for P).
struct UlogParameter {
  std::string name;
  double value = 0;
  int default_types = 0;
  std::uint64_t offset = 0;  // byte offset of the message
};

// An `L` or `C` message. `tag` is -1 for untagged strings.
struct UlogLoggedString {
  int level = 0;  // 0 emergency ... 7 debug
  int tag = -1;
  std::uint64_t timestamp_us = 0;
  std::string text;
};

// What the reader skipped or repaired; each count is also described once in
// UlogData::warnings with its byte offset.
struct UlogParseStats {
  std::size_t messages = 0;        // message headers processed
  std::size_t resyncs = 0;         // corruption → scan for the sync magic
  std::size_t skipped_bytes = 0;   // bytes passed over while resyncing
  std::size_t unknown_msg_id = 0;  // D messages whose msg_id is not subscribed
  std::size_t bad_data_size = 0;   // D payload neither S_logged..S_full
  std::size_t unknown_types = 0;   // messages of an unknown type, skipped
  std::size_t dropped_at_boundary = 0;    // cut by an appended-data offset
  std::size_t truncated_tail_bytes = 0;   // incomplete last message, dropped
  std::size_t skipped_topic_samples = 0;  // D of topics not asked for
};

struct UlogData {
  int version = 0;                       // header version byte
  std::uint64_t start_timestamp_us = 0;  // header timestamp
  bool has_flag_bits = false;            // a `B` message was present
  std::uint8_t compat_flags[8] = {};
  std::uint8_t incompat_flags[8] = {};
  std::vector<std::uint64_t> appended_offsets;  // the non-zero ones

  std::vector<UlogInfo> info;
  std::vector<UlogMultiInfo> multi_info;
  // Parameters from the definitions section (the initial values), in file
  // order; a name seen twice keeps the later value.
  std::vector<UlogParameter> parameters;
  // `P` messages in the data section (in-flight changes), in file order.
  std::vector<UlogParameter> parameter_changes;
  std::vector<UlogParameter> default_parameters;  // `Q`
  std::vector<UlogTopic> topics;                  // in subscription order
  std::vector<UlogLoggedString> logged_strings;
  int dropout_count = 0;
  double dropout_total_ms = 0;

  UlogParseStats stats;
  // Human-readable notes on every repair, "byte N: ...", at most
  // kMaxUlogWarnings (then one final "... more" line).
  std::vector<std::string> warnings;

  const UlogTopic* FindTopic(std::string_view name, int multi_id = 0) const;
  const UlogInfo* FindInfo(std::string_view key) const;
  const UlogMultiInfo* FindMultiInfo(std::string_view key) const;
  // The initial value of parameter `name`.
  std::optional<double> FindParameter(std::string_view name) const;
};

inline constexpr std::size_t kMaxUlogWarnings = 50;

struct UlogReadOptions {
  // When non-empty, only topics with these names are decoded (the others are
  // still validated and counted in stats.skipped_topic_samples). Makes
  // reading the IMU out of a large log cheaper.
  std::vector<std::string> topics;
};

// True when `bytes` starts with the ULog magic.
bool LooksLikeUlog(std::string_view bytes);

// Parses a whole ULog file image. `name` prefixes error messages.
// Hard failures (InvalidArgument "name: byte N: ..."): wrong magic or a file
// shorter than the header, an unknown incompat flag bit, a malformed `F`, a
// subscription whose format (or a nested type) is undefined or recursive or
// too large. Everything else is repaired and reported in stats/warnings:
// truncated last message dropped, implausible headers resynchronised on the
// `S` magic, D with unknown msg_id or wrong size skipped, unknown message
// types skipped. Linear in the file size; memory bounded by a small multiple
// of it.
StatusOr<UlogData> ParseUlog(std::string_view bytes,
                             const std::string& name,
                             const UlogReadOptions& options = {});

// Reads `path` and calls ParseUlog.
StatusOr<UlogData> ReadUlog(const std::string& path,
                            const UlogReadOptions& options = {});

}  // namespace imusysid

#endif  // IMUSYSID_ULOG_H_
