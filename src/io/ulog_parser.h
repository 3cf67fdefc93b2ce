// The ULog parser behind ParseUlog (imusysid/ulog.h), shared by the files
// that implement it: the definitions and parameters (ulog_definitions.cc)
// and the data section and resynchronisation (ulog_reader.cc). Internal.

#ifndef IMUSYSID_SRC_IO_ULOG_PARSER_H_
#define IMUSYSID_SRC_IO_ULOG_PARSER_H_

#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "imusysid/status.h"
#include "imusysid/ulog.h"

namespace imusysid {
namespace ulog_internal {

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

inline const BasicTypeInfo* FindBasicType(std::string_view name) {
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

inline double DecodeBasic(BasicType type, const unsigned char* p) {
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

}  // namespace ulog_internal
}  // namespace imusysid

#endif  // IMUSYSID_SRC_IO_ULOG_PARSER_H_
