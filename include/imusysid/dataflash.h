// Reader for ArduPilot DataFlash binary logs (.bin): FMT-described records
// decoded into per-message columns reachable as "MSG.Field", with
// resynchronisation on corrupt bytes (shared/docs/ulog-format.md, part B).

#ifndef IMUSYSID_DATAFLASH_H_
#define IMUSYSID_DATAFLASH_H_

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "imusysid/status.h"

namespace imusysid {

// All records of one message type (one FMT id).
struct DataFlashMessage {
  std::string name;    // "IMU", "ATT", ...
  int type_id = 0;     // the FMT `type` byte (not stable across firmware)
  int length = 0;      // record length including the 3-byte header
  std::string format;  // format letters, e.g. "IffffffIIf"
  std::vector<std::string> labels;  // one per letter
  std::uint64_t fmt_offset = 0;     // byte offset of the defining FMT

  // Numeric fields (every letter except n, N, Z, a) in field order, scaled
  // by the letter's implied factor: c, C, e, E ×0.01; L ×1e-7; g is a half
  // float.
  std::vector<std::string> column_names;
  std::vector<std::vector<double>> columns;
  // Text fields (n, N, Z), NUL-trimmed. `a` (int16[32]) is not kept.
  std::vector<std::string> string_column_names;
  std::vector<std::vector<std::string>> string_columns;
  // Byte offset of each record.
  std::vector<std::uint64_t> offsets;

  std::size_t size() const { return offsets.size(); }
  const std::vector<double>* FindColumn(std::string_view field) const;
  const std::vector<std::string>* FindStringColumn(
      std::string_view field) const;
};

// What the reader skipped or repaired; each kind is described once in
// DataFlashLog::warnings with a byte offset.
struct DataFlashParseStats {
  std::size_t records = 0;  // data records decoded (FMT included)
  std::size_t fmt_records = 0;
  std::size_t resyncs = 0;               // times the stream lost sync
  std::size_t skipped_bytes = 0;         // bytes passed over while resyncing
  std::size_t truncated_tail_bytes = 0;  // incomplete last record
  std::size_t fmt_conflicts = 0;         // FMT redefining an id differently
  std::size_t rejected_fmts = 0;         // FMT with bad letters or length
};

struct DataFlashLog {
  std::vector<DataFlashMessage> messages;  // in order of definition
  // PARM Name → Value in file order (a name set twice appears twice).
  std::vector<std::pair<std::string, double>> parameters;
  // MSG texts in file order.
  std::vector<std::string> texts;
  DataFlashParseStats stats;
  // "byte N: ..." notes, at most kMaxDataFlashWarnings (+ one "... more").
  std::vector<std::string> warnings;

  const DataFlashMessage* FindMessage(std::string_view name) const;
  // "MSG.Field" → the column, or nullptr.
  const std::vector<double>* FindColumn(std::string_view qualified) const;
  // The last value PARM set for `name`.
  std::optional<double> FindParameter(std::string_view name) const;
};

inline constexpr std::size_t kMaxDataFlashWarnings = 50;

struct DataFlashReadOptions {
  // When non-empty, only messages with these names have their fields
  // decoded; the others keep their definition and record offsets (so size()
  // still counts their records) but their columns stay empty, and PARM and
  // MSG feed `parameters` and `texts` only when listed. Decoding every field
  // of every message as a double is most of a full read's memory and time;
  // reading the IMU needs a few messages.
  std::vector<std::string> messages;
};

// True when `bytes` starts with A3 95 80 (the FMT record describing FMT).
bool LooksLikeDataFlash(std::string_view bytes);

// Size in bytes of a FMT format letter (b B M: 1, h H c C g: 2, i I f e E L
// n: 4, d q Q: 8, N: 16, Z a: 64), 0 for an unknown letter: what the reader
// decodes a record by, and what a writer lays one out by.
int DataFlashLetterSize(char letter);

// Parses a whole DataFlash file image; `name` prefixes error messages.
//
// Records are `A3 95 id payload`, the layout given by the id's FMT record.
// FMT records are honoured anywhere in the file. A FMT whose length is not
// 3 + Σ letter sizes, or with an unknown letter, is rejected (warning). A FMT
// for an id that is already defined with a different layout is ignored: the
// first definition is kept, so the result never depends on which of two
// conflicting layouts came last (warning with both offsets). The FMT id 128
// always keeps its built-in 89-byte layout. Bytes that do not start a known
// record are skipped one at a time until `A3 95 <known id>` (counted). An
// incomplete last record is dropped.
//
// Hard failures (InvalidArgument "name: byte N: ..."): the file does not
// start with A3 95 80, or it holds no FMT record that could be decoded.
// Linear time; memory proportional to the file size.
StatusOr<DataFlashLog> ParseDataFlash(
    std::string_view bytes,
    const std::string& name,
    const DataFlashReadOptions& options = DataFlashReadOptions());

// Reads `path` and calls ParseDataFlash.
StatusOr<DataFlashLog> ReadDataFlash(const std::string& path);

}  // namespace imusysid

#endif  // IMUSYSID_DATAFLASH_H_
