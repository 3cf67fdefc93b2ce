// Problem files: the preprocessed samples an estimator fits (ProblemData) as
// a CSV with named columns t,f,omega,omega_dot,v (SI units), so other tools
// can hand imusysid their own regressors and peers can fit the same numbers.
// The format is described in docs/problem-files.md.

#ifndef IMUSYSID_PROBLEM_IO_H_
#define IMUSYSID_PROBLEM_IO_H_

#include <cstddef>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "imusysid/problem_data.h"
#include "imusysid/status.h"

namespace imusysid {

// '# key: value' lines of a problem file, in file order.
using ProblemMetadata = std::vector<std::pair<std::string, std::string>>;

// What a problem file holds besides the samples.
struct ProblemFile {
  // data.source is the file's name; data.gravity comes from the 'gravity'
  // metadata (kGravity when absent); theta and f_z are filled when the file
  // has those optional columns, else empty.
  ProblemData data;
  ProblemMetadata metadata;
  // Header columns that are neither required nor known optional columns, in
  // header order. They are checked for the row's field count but not parsed.
  std::vector<std::string> ignored_columns;

  // Returns the metadata value for `key`, or nullptr.
  const std::string* FindMetadata(std::string_view key) const;
};

// Required columns, in the order the writer uses, and the optional ones the
// reader understands.
std::vector<std::string> ProblemRequiredColumns();  // t,f,omega,omega_dot,v
std::vector<std::string> ProblemOptionalColumns();  // theta,f_z

// Fewer data rows than this is an error (the same floor as a log's).
inline constexpr std::size_t kMinProblemSamples = 10;

// Serialises `data` with 17 significant digits (parsing the text gives back
// the same doubles): a title comment, `metadata` as '# key: value' lines, a
// '# gravity:' line from data.gravity (a 'gravity' entry in `metadata` is
// skipped so the two cannot disagree), the header and one row per sample.
// theta and f_z are written when present. InvalidArgument when `data` is
// not valid (ProblemData::Validate) or its gravity is not finite.
StatusOr<std::string> FormatProblemCsv(const ProblemData& data,
                                       const ProblemMetadata& metadata = {});

// FormatProblemCsv + WriteFileAtomically.
Status WriteProblemCsv(const std::string& path,
                       const ProblemData& data,
                       const ProblemMetadata& metadata = {});

// Parses problem CSV text; `name` is used in messages and as data.source.
// Columns are found by name in any order. Every malformed input is an
// InvalidArgument of the form "name:line:column: message" naming the column
// and the offending text: a missing header or required column, an empty,
// non-numeric, NaN or infinite cell, a row with the wrong number of fields,
// t not strictly increasing, a bad 'gravity' value, or fewer than
// kMinProblemSamples rows.
StatusOr<ProblemFile> ParseProblemCsv(std::string_view text,
                                      const std::string& name);

// Reads and parses a problem file (NotFound / IoError when it cannot be read).
StatusOr<ProblemFile> ReadProblemCsv(const std::string& path);

}  // namespace imusysid

#endif  // IMUSYSID_PROBLEM_IO_H_
