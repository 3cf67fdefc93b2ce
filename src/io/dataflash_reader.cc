#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <utility>

#include "imusysid/dataflash.h"
#include "imusysid/log.h"

namespace imusysid {
namespace {

constexpr unsigned char kHead1 = 0xA3;
constexpr unsigned char kHead2 = 0x95;
constexpr int kFmtId = 128;
constexpr int kFmtLength = 89;
constexpr std::size_t kRecordHeader = 3;

bool IsStringLetter(char letter) {
  return letter == 'n' || letter == 'N' || letter == 'Z';
}

template <typename T>
T Load(const unsigned char* p) {
  T value;
  std::memcpy(&value, p, sizeof(T));
  return value;
}

double HalfToDouble(std::uint16_t bits) {
  const int sign = (bits >> 15) != 0 ? -1 : 1;
  const int exponent = (bits >> 10) & 0x1F;
  const int mantissa = bits & 0x3FF;
  if (exponent == 0) return sign * std::ldexp(mantissa, -24);
  if (exponent == 31) {
    return mantissa == 0 ? sign * HUGE_VAL : std::nan("");
  }
  return sign * std::ldexp(mantissa + 1024, exponent - 25);
}

double DecodeNumber(char letter, const unsigned char* p) {
  switch (letter) {
    case 'b':
      return Load<std::int8_t>(p);
    case 'B':
    case 'M':
      return *p;
    case 'h':
      return Load<std::int16_t>(p);
    case 'H':
      return Load<std::uint16_t>(p);
    case 'c':
      return Load<std::int16_t>(p) * 0.01;
    case 'C':
      return Load<std::uint16_t>(p) * 0.01;
    case 'g':
      return HalfToDouble(Load<std::uint16_t>(p));
    case 'i':
      return Load<std::int32_t>(p);
    case 'I':
      return Load<std::uint32_t>(p);
    case 'f':
      return Load<float>(p);
    case 'e':
      return Load<std::int32_t>(p) * 0.01;
    case 'E':
      return Load<std::uint32_t>(p) * 0.01;
    case 'L':
      return Load<std::int32_t>(p) * 1e-7;
    case 'd':
      return Load<double>(p);
    case 'q':
      return static_cast<double>(Load<std::int64_t>(p));
    case 'Q':
      return static_cast<double>(Load<std::uint64_t>(p));
    default:
      return 0;
  }
}

std::string TrimmedText(const unsigned char* p, std::size_t n) {
  std::size_t len = 0;
  while (len < n && p[len] != 0) ++len;
  return std::string(reinterpret_cast<const char*>(p), len);
}

struct FieldSlot {
  std::uint32_t offset;  // within the record, header included
  char letter;
  int index;  // into columns or string_columns; -1 = not kept (`a`)
};

struct Layout {
  std::size_t message_index;
  std::vector<FieldSlot> slots;
  // False for a message DataFlashReadOptions::messages leaves out: only its
  // record offsets are kept.
  bool decode = true;
  // PARM and MSG records also feed DataFlashLog::parameters and texts; these
  // are the columns they read (-1: none), found once here rather than by
  // name for every record.
  int parameter_name = -1;   // string column
  int parameter_value = -1;  // numeric column
  int text = -1;             // string column
};

// Index of the first `name` in `names`, or -1.
int IndexOf(const std::vector<std::string>& names, const char* name) {
  for (std::size_t k = 0; k < names.size(); ++k) {
    if (names[k] == name) return static_cast<int>(k);
  }
  return -1;
}

class Parser {
 public:
  Parser(std::string_view bytes,
         const std::string& name,
         const DataFlashReadOptions& options)
      : data_(reinterpret_cast<const unsigned char*>(bytes.data())),
        size_(bytes.size()),
        name_(name),
        options_(options) {}

  StatusOr<DataFlashLog> Parse();

 private:
  void Warn(std::uint64_t offset, const std::string& what) {
    if (out_.warnings.size() < kMaxDataFlashWarnings) {
      out_.warnings.push_back("byte " + std::to_string(offset) + ": " + what);
    } else if (out_.warnings.size() == kMaxDataFlashWarnings) {
      out_.warnings.push_back("... more warnings not shown");
    }
  }
  void CountRecords();
  void HandleFmt(std::size_t pos);
  void Decode(std::size_t pos, const Layout& layout);

  const unsigned char* data_;
  std::size_t size_;
  const std::string& name_;
  const DataFlashReadOptions& options_;
  DataFlashLog out_;
  int lengths_[256] = {};  // record length per id, 0 = undefined
  int layout_index_[256];  // into layouts_, -1 for FMT/undefined
  std::vector<Layout> layouts_;
  // Records per id from CountRecords, to size the columns once.
  std::array<std::size_t, 256> counts_ = {};
};

// Counts the records of each id by walking the record headers with the
// lengths the FMT records declare, stopping at the first byte that does not
// start a complete record. The counts only size the columns: the decoding
// pass checks everything itself, and a column whose count fell short (a
// damaged log, an FMT the decoder rejects) just grows. Without them the
// columns grew by doubling, each step copying and touching fresh memory,
// which was most of the reader's time.
void Parser::CountRecords() {
  std::size_t lengths[256] = {};
  lengths[kFmtId] = kFmtLength;
  std::size_t pos = 0;
  while (size_ - pos >= kRecordHeader && data_[pos] == kHead1 &&
         data_[pos + 1] == kHead2) {
    const int id = data_[pos + 2];
    const std::size_t length = lengths[id];
    if (length == 0 || length > size_ - pos) break;
    if (id == kFmtId) {
      const int type = data_[pos + kRecordHeader];
      const std::size_t declared = data_[pos + kRecordHeader + 1];
      if (lengths[type] == 0 && declared >= kRecordHeader) {
        lengths[type] = declared;
      }
    }
    ++counts_[static_cast<std::size_t>(id)];
    pos += length;
  }
}

void Parser::HandleFmt(std::size_t pos) {
  const unsigned char* p = data_ + pos + kRecordHeader;
  ++out_.stats.fmt_records;
  const int type = p[0];
  const int length = p[1];
  DataFlashMessage message;
  message.name = TrimmedText(p + 2, 4);
  message.type_id = type;
  message.length = length;
  message.format = TrimmedText(p + 6, 16);
  message.fmt_offset = pos;
  const std::string labels = TrimmedText(p + 22, 64);

  if (lengths_[type] != 0) {
    // Keep the first definition; an identical repeat is harmless.
    bool same = false;
    if (type == kFmtId) {
      same = length == kFmtLength && message.format == "BBnNZ";
    } else {
      const DataFlashMessage& first =
          out_.messages[layouts_[static_cast<std::size_t>(layout_index_[type])]
                            .message_index];
      same = first.length == length && first.format == message.format &&
             first.name == message.name;
    }
    if (!same) {
      ++out_.stats.fmt_conflicts;
      Warn(pos,
           "FMT redefines id " + std::to_string(type) + " as '" + message.name +
               "' (" + message.format + ", " + std::to_string(length) +
               " bytes); ignored, the first definition is kept");
    }
    return;
  }
  if (type == kFmtId) {
    // Only the built-in layout can be framed; anything else would be a lie.
    if (length != kFmtLength || message.format != "BBnNZ") {
      ++out_.stats.fmt_conflicts;
      Warn(pos,
           "FMT describing FMT with layout '" + message.format +
               "' ignored; the built-in 89-byte layout is kept");
    }
    lengths_[kFmtId] = kFmtLength;
    return;
  }
  int total = static_cast<int>(kRecordHeader);
  for (char letter : message.format) {
    const int size = DataFlashLetterSize(letter);
    if (size == 0) {
      ++out_.stats.rejected_fmts;
      Warn(pos,
           "FMT for '" + message.name + "' has unknown format letter '" +
               std::string(1, letter) + "'; its records are skipped");
      return;
    }
    total += size;
  }
  if (total != length || message.name.empty()) {
    ++out_.stats.rejected_fmts;
    Warn(pos,
         "FMT for '" + message.name + "' (" + message.format +
             ") declares length " + std::to_string(length) +
             " but its letters need " + std::to_string(total) +
             "; its records are skipped");
    return;
  }
  std::size_t start = 0;
  while (start <= labels.size()) {
    const std::size_t comma = labels.find(',', start);
    const std::size_t stop = comma == std::string::npos ? labels.size() : comma;
    message.labels.push_back(labels.substr(start, stop - start));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (labels.empty()) message.labels.clear();
  if (message.labels.size() != message.format.size()) {
    Warn(pos,
         "FMT for '" + message.name + "' has " +
             std::to_string(message.labels.size()) + " labels for " +
             std::to_string(message.format.size()) +
             " fields; missing ones are named fieldN");
    message.labels.resize(message.format.size());
    for (std::size_t i = 0; i < message.labels.size(); ++i) {
      if (message.labels[i].empty()) {
        message.labels[i] = "field" + std::to_string(i);
      }
    }
  }
  Layout layout;
  layout.message_index = out_.messages.size();
  std::uint32_t offset = kRecordHeader;
  for (std::size_t i = 0; i < message.format.size(); ++i) {
    const char letter = message.format[i];
    FieldSlot slot{offset, letter, -1};
    if (IsStringLetter(letter)) {
      slot.index = static_cast<int>(message.string_column_names.size());
      message.string_column_names.push_back(message.labels[i]);
    } else if (letter != 'a') {
      slot.index = static_cast<int>(message.column_names.size());
      message.column_names.push_back(message.labels[i]);
    }
    layout.slots.push_back(slot);
    offset += static_cast<std::uint32_t>(DataFlashLetterSize(letter));
  }
  message.columns.resize(message.column_names.size());
  message.string_columns.resize(message.string_column_names.size());
  layout.decode = options_.messages.empty() ||
                  std::find(options_.messages.begin(),
                            options_.messages.end(),
                            message.name) != options_.messages.end();
  const std::size_t expected = counts_[static_cast<std::size_t>(type)];
  message.offsets.reserve(expected);
  if (!layout.decode) {
    // Neither columns nor PARM/MSG bookkeeping for a message left out.
  } else if (message.name == "PARM") {
    layout.parameter_name = IndexOf(message.string_column_names, "Name");
    layout.parameter_value = IndexOf(message.column_names, "Value");
  } else if (message.name == "MSG") {
    layout.text = IndexOf(message.string_column_names, "Message");
  }
  if (layout.decode) {
    for (std::vector<double>& column : message.columns) {
      column.reserve(expected);
    }
    for (std::vector<std::string>& column : message.string_columns) {
      column.reserve(expected);
    }
  }
  for (const DataFlashMessage& existing : out_.messages) {
    if (existing.name == message.name) {
      Warn(pos,
           "message name '" + message.name + "' defined again for id " +
               std::to_string(type) + "; lookups by name find id " +
               std::to_string(existing.type_id));
      break;
    }
  }
  lengths_[type] = length;
  layout_index_[type] = static_cast<int>(layouts_.size());
  layouts_.push_back(std::move(layout));
  out_.messages.push_back(std::move(message));
}

void Parser::Decode(std::size_t pos, const Layout& layout) {
  DataFlashMessage& message = out_.messages[layout.message_index];
  if (!layout.decode) {
    message.offsets.push_back(pos);
    return;
  }
  const unsigned char* record = data_ + pos;
  for (const FieldSlot& slot : layout.slots) {
    if (slot.index < 0) continue;
    const unsigned char* at = record + slot.offset;
    const auto index = static_cast<std::size_t>(slot.index);
    if (IsStringLetter(slot.letter)) {
      message.string_columns[index].push_back(TrimmedText(
          at, static_cast<std::size_t>(DataFlashLetterSize(slot.letter))));
    } else {
      message.columns[index].push_back(DecodeNumber(slot.letter, at));
    }
  }
  message.offsets.push_back(pos);
  if (layout.parameter_name >= 0 && layout.parameter_value >= 0) {
    out_.parameters.emplace_back(
        message.string_columns[static_cast<std::size_t>(layout.parameter_name)]
            .back(),
        message.columns[static_cast<std::size_t>(layout.parameter_value)]
            .back());
  } else if (layout.text >= 0) {
    out_.texts.push_back(
        message.string_columns[static_cast<std::size_t>(layout.text)].back());
  }
}

StatusOr<DataFlashLog> Parser::Parse() {
  if (!LooksLikeDataFlash(
          std::string_view(reinterpret_cast<const char*>(data_), size_))) {
    return InvalidArgumentError(
        name_ + ": byte 0: not a DataFlash log (expected A3 95 80)");
  }
  for (int& index : layout_index_) index = -1;
  lengths_[kFmtId] = kFmtLength;
  CountRecords();
  std::size_t pos = 0;
  bool in_sync = true;
  while (pos < size_) {
    if (size_ - pos >= kRecordHeader && data_[pos] == kHead1 &&
        data_[pos + 1] == kHead2) {
      const int id = data_[pos + 2];
      const auto length = static_cast<std::size_t>(lengths_[id]);
      if (length != 0 && length <= size_ - pos) {
        if (id == kFmtId) {
          HandleFmt(pos);
        } else {
          Decode(pos, layouts_[static_cast<std::size_t>(layout_index_[id])]);
        }
        ++out_.stats.records;
        pos += length;
        in_sync = true;
        continue;
      }
      if (length != 0) {
        // A known record running past the end: the log was cut off, unless
        // another record header follows (then the length is a lie).
        const unsigned char* next = data_ + pos + 1;
        bool header_follows = false;
        while ((next = static_cast<const unsigned char*>(std::memchr(
                    next,
                    kHead1,
                    static_cast<std::size_t>(data_ + size_ - next)))) !=
               nullptr) {
          if (next + 1 < data_ + size_ && next[1] == kHead2) {
            header_follows = true;
            break;
          }
          ++next;
        }
        if (!header_follows) {
          out_.stats.truncated_tail_bytes += size_ - pos;
          Warn(pos, "truncated last record dropped");
          break;
        }
      }
    } else if (size_ - pos < kRecordHeader) {
      out_.stats.truncated_tail_bytes += size_ - pos;
      Warn(pos, "incomplete record header at end of file dropped");
      break;
    }
    if (in_sync) {
      ++out_.stats.resyncs;
      Warn(pos, "lost record sync; scanning for the next A3 95 <known id>");
      in_sync = false;
    }
    const void* next = std::memchr(data_ + pos + 1, kHead1, size_ - pos - 1);
    const std::size_t next_pos =
        next == nullptr ? size_
                        : static_cast<std::size_t>(
                              static_cast<const unsigned char*>(next) - data_);
    out_.stats.skipped_bytes += next_pos - pos;
    pos = next_pos;
  }
  if (out_.stats.fmt_records == 0) {
    return InvalidArgumentError(name_ +
                                ": byte 0: no complete FMT record in the file");
  }
  return std::move(out_);
}

}  // namespace

int DataFlashLetterSize(char letter) {
  switch (letter) {
    case 'b':
    case 'B':
    case 'M':
      return 1;
    case 'h':
    case 'H':
    case 'c':
    case 'C':
    case 'g':
      return 2;
    case 'i':
    case 'I':
    case 'f':
    case 'e':
    case 'E':
    case 'L':
    case 'n':
      return 4;
    case 'd':
    case 'q':
    case 'Q':
      return 8;
    case 'N':
      return 16;
    case 'Z':
    case 'a':
      return 64;
    default:
      return 0;
  }
}

const std::vector<double>* DataFlashMessage::FindColumn(
    std::string_view field) const {
  for (std::size_t k = 0; k < column_names.size(); ++k) {
    if (column_names[k] == field) return &columns[k];
  }
  return nullptr;
}

const std::vector<std::string>* DataFlashMessage::FindStringColumn(
    std::string_view field) const {
  for (std::size_t k = 0; k < string_column_names.size(); ++k) {
    if (string_column_names[k] == field) return &string_columns[k];
  }
  return nullptr;
}

const DataFlashMessage* DataFlashLog::FindMessage(std::string_view name) const {
  for (const DataFlashMessage& message : messages) {
    if (message.name == name) return &message;
  }
  return nullptr;
}

const std::vector<double>* DataFlashLog::FindColumn(
    std::string_view qualified) const {
  const std::size_t dot = qualified.find('.');
  if (dot == std::string_view::npos) return nullptr;
  const DataFlashMessage* message = FindMessage(qualified.substr(0, dot));
  return message == nullptr ? nullptr
                            : message->FindColumn(qualified.substr(dot + 1));
}

std::optional<double> DataFlashLog::FindParameter(std::string_view name) const {
  std::optional<double> value;
  for (const auto& [key, v] : parameters) {
    if (key == name) value = v;
  }
  return value;
}

bool LooksLikeDataFlash(std::string_view bytes) {
  return bytes.size() >= 3 && static_cast<unsigned char>(bytes[0]) == kHead1 &&
         static_cast<unsigned char>(bytes[1]) == kHead2 &&
         static_cast<unsigned char>(bytes[2]) == kFmtId;
}

StatusOr<DataFlashLog> ParseDataFlash(std::string_view bytes,
                                      const std::string& name,
                                      const DataFlashReadOptions& options) {
  Parser parser(bytes, name, options);
  return parser.Parse();
}

StatusOr<DataFlashLog> ReadDataFlash(const std::string& path) {
  StatusOr<std::string> bytes = ReadFileToString(path);
  if (!bytes.ok()) return bytes.status();
  return ParseDataFlash(*bytes, path);
}

}  // namespace imusysid
