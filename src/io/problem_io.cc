#include "imusysid/problem_io.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <string>
#include <system_error>

#include "imusysid/log.h"
#include "src/io/csv_text.h"
#include "src/tools/format.h"

namespace imusysid {
namespace {

using internal::CharColumn;
using internal::ErrorAt;
using internal::IsBlank;
using internal::ParseMetadata;
using internal::Quote;
using internal::TrimBlanks;

// 17 significant digits identify every double, so a written file reads back
// bit for bit (up to the sign of zero).
constexpr int kDigits = 17;

constexpr const char* kTitle =
    "# imusysid problem file: the preprocessed samples of the paper's "
    "equation 9 (docs/problem-files.md)";

// Column roles; the order of the writer.
enum Role { kT, kF, kOmega, kOmegaDot, kV, kTheta, kFz, kNumRoles, kIgnored };
constexpr int kNumRequired = 5;
constexpr const char* kRoleNames[kNumRoles] = {
    "t", "f", "omega", "omega_dot", "v", "theta", "f_z"};

// One comma-separated field: its text without surrounding blanks and where
// that text starts (the line's end for an empty last field).
struct Field {
  std::string_view text;
  const char* start;
};

// Fills `fields` (cleared first; its capacity is reused from row to row).
void SplitFields(std::string_view line, std::vector<Field>* fields) {
  fields->clear();
  const char* p = line.data();
  const char* const end = p + line.size();
  while (true) {
    const char* stop = p;
    while (stop < end && *stop != ',') ++stop;
    const char* start = p;
    while (start < stop && IsBlank(*start)) ++start;
    fields->push_back(
        {TrimBlanks(std::string_view(start, static_cast<size_t>(stop - start))),
         start});
    if (stop == end) break;
    p = stop + 1;
  }
}

// The gravity a problem file may declare, m/s^2 (the Moon's is 1.6,
// Jupiter's 24.8).
constexpr double kMinGravity = 0.1;
constexpr double kMaxGravity = 100.0;

enum class NumberError {
  kNone,
  kEmpty,
  kNotANumber,
  kOutOfRange,
  kNotFinite,
  kTooLarge
};

// Parses a whole field as a double. A leading '+' is accepted because
// spreadsheets write it.
NumberError ParseNumber(std::string_view text, double* value) {
  if (text.empty()) return NumberError::kEmpty;
  const char* first = text.data();
  const char* const last = text.data() + text.size();
  if (*first == '+' && text.size() > 1 && first[1] != '+' && first[1] != '-') {
    ++first;
  }
  const std::from_chars_result r = std::from_chars(first, last, *value);
  if (r.ec == std::errc::result_out_of_range) return NumberError::kOutOfRange;
  if (r.ec != std::errc() || r.ptr != last) return NumberError::kNotANumber;
  if (!std::isfinite(*value)) return NumberError::kNotFinite;
  // Finite but beyond what any regressor holds: its square, formed by every
  // estimator, would overflow (an SVD of such a matrix crashed `linear`).
  if (std::abs(*value) > kMaxAbsInputValue) return NumberError::kTooLarge;
  return NumberError::kNone;
}

// Parses a data row in the form writers produce (FormatProblemCsv,
// spreadsheets, pandas): every column in `dest` (null for an ignored column,
// whose text is skipped) a number without blanks or '+' within
// +/-kMaxAbsInputValue, exactly one field per header column, the line ended by
// "\n", "\r\n" or the end of the text. Stores the values in `row` and the t
// field in `t_field`, and returns where the row's text ends (before its line
// break). Returns nullptr for any other form (blank and comment lines
// included), which the general path then reads and reports as it always has:
// both take the numbers from std::from_chars over the same characters, so
// the values are identical.
inline const char* ParsePlainRow(const char* p,
                                 const char* end,
                                 const std::vector<std::vector<double>*>& dest,
                                 std::size_t t_column,
                                 double* row,
                                 Field* t_field) {
  if (p == end || IsBlank(*p) || *p == '#' || *p == '\r' || *p == '\n') {
    return nullptr;
  }
  const std::size_t num_columns = dest.size();
  for (std::size_t c = 0;;) {
    const char* start = p;
    if (dest[c] == nullptr) {
      while (p < end && *p != ',' && *p != '\n') ++p;
    } else {
      const std::from_chars_result r = std::from_chars(p, end, row[c]);
      if (r.ec != std::errc() || !(std::abs(row[c]) <= kMaxAbsInputValue)) {
        return nullptr;
      }
      p = r.ptr;
    }
    if (c == t_column) {
      *t_field = {std::string_view(start, static_cast<size_t>(p - start)),
                  start};
    }
    if (++c == num_columns) break;
    if (p == end || *p != ',') return nullptr;
    ++p;
  }
  return internal::RowEndAt(p, end);
}

std::string NumberMessage(NumberError error, std::string_view text) {
  switch (error) {
    case NumberError::kEmpty:
      return "empty cell";
    case NumberError::kNotANumber:
      return Quote(text) + " is not a number";
    case NumberError::kOutOfRange:
      return Quote(text) + " is outside the range of a double";
    case NumberError::kNotFinite:
      return Quote(text) + " is not a finite number";
    case NumberError::kTooLarge:
      return Quote(text) +
             " is beyond +/-1e100, the largest magnitude a problem file may "
             "hold (its square would overflow in the fit)";
    case NumberError::kNone:
      break;
  }
  return "";
}

std::string JoinQuoted(const std::vector<std::string>& names) {
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i > 0) out += ", ";
    out += "'" + names[i] + "'";
  }
  return out;
}

std::string RequiredList() {
  std::string out;
  for (int r = 0; r < kNumRequired; ++r) {
    if (r > 0) out += ",";
    out += kRoleNames[r];
  }
  return out;
}

// Metadata must stay on one line or the file would not read back.
std::string OneLine(std::string_view text) {
  std::string out(text);
  for (char& c : out) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return out;
}

}  // namespace

const std::string* ProblemFile::FindMetadata(std::string_view key) const {
  for (const auto& entry : metadata) {
    if (entry.first == key) return &entry.second;
  }
  return nullptr;
}

std::vector<std::string> ProblemRequiredColumns() {
  return std::vector<std::string>(kRoleNames, kRoleNames + kNumRequired);
}

std::vector<std::string> ProblemOptionalColumns() {
  return std::vector<std::string>(kRoleNames + kNumRequired,
                                  kRoleNames + kNumRoles);
}

StatusOr<std::string> FormatProblemCsv(const ProblemData& data,
                                       const ProblemMetadata& metadata) {
  IMUSYSID_RETURN_IF_ERROR(data.Validate());
  if (!data.motion.empty()) {
    return InvalidArgumentError(
        data.source +
        ": these data carry the 3-D motion; a problem file holds planar "
        "data only (docs/problem-files.md)");
  }
  if (!std::isfinite(data.gravity)) {
    std::ostringstream msg;
    msg << data.source << ": gravity = " << data.gravity << "; required finite";
    return InvalidArgumentError(msg.str());
  }
  const std::size_t n = data.size();
  std::vector<const std::vector<double>*> columns = {&data.t_s,
                                                     &data.planar.f_x,
                                                     &data.planar.omega,
                                                     &data.planar.omega_dot,
                                                     &data.planar.v};
  std::string header = RequiredList();
  if (!data.planar.theta.empty()) {
    columns.push_back(&data.planar.theta);
    header += ",theta";
  }
  if (!data.planar.f_z.empty()) {
    columns.push_back(&data.planar.f_z);
    header += ",f_z";
  }

  std::string out;
  // A 17-digit value with sign, point and exponent takes at most 24 bytes.
  out.reserve(512 + n * columns.size() * 25);
  out += kTitle;
  out += '\n';
  for (const auto& entry : metadata) {
    if (entry.first == "gravity") continue;
    out += "# " + OneLine(entry.first) + ": " + OneLine(entry.second) + "\n";
  }
  out += "# gravity: ";
  AppendNumber(&out, data.gravity, kDigits);
  out += '\n';
  out += header;
  out += '\n';
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t c = 0; c < columns.size(); ++c) {
      if (c > 0) out += ',';
      AppendNumber(&out, (*columns[c])[i], kDigits);
    }
    out += '\n';
  }
  return out;
}

Status WriteProblemCsv(const std::string& path,
                       const ProblemData& data,
                       const ProblemMetadata& metadata) {
  StatusOr<std::string> text = FormatProblemCsv(data, metadata);
  if (!text.ok()) return text.status();
  return WriteFileAtomically(path, *text);
}

StatusOr<ProblemFile> ParseProblemCsv(std::string_view text,
                                      const std::string& name) {
  ProblemFile file;
  ProblemData& data = file.data;
  data.source = name;
  data.gravity = kGravity;

  std::string_view body = text;
  if (body.size() >= 3 && body.substr(0, 3) == "\xEF\xBB\xBF") {
    body.remove_prefix(3);
  }

  // Lines without their terminator and trailing blanks or '\r'.
  std::size_t pos = 0;
  int line_number = 0;
  std::string_view line;
  auto next_line = [&]() -> bool {
    if (pos >= body.size()) return false;
    std::size_t stop = body.find('\n', pos);
    if (stop == std::string_view::npos) stop = body.size();
    line = body.substr(pos, stop - pos);
    pos = stop + 1;
    while (!line.empty() && (line.back() == '\r' || IsBlank(line.back()))) {
      line.remove_suffix(1);
    }
    ++line_number;
    return true;
  };
  enum class Kind { kBlank, kComment, kContent };
  auto classify = [](std::string_view l) {
    const std::string_view trimmed = TrimBlanks(l);
    if (trimmed.empty()) return Kind::kBlank;
    return trimmed.front() == '#' ? Kind::kComment : Kind::kContent;
  };
  // Comments may appear anywhere; metadata keeps file order.
  auto handle_comment = [&](std::string_view comment) -> Status {
    std::string_view key, value;
    if (!ParseMetadata(comment, &key, &value)) return Status::Ok();
    if (key == "gravity") {
      double g = 0.0;
      const NumberError e = ParseNumber(value, &g);
      // A plausible range rather than just > 0: a typo such as 1e300 or
      // 9806.65 (mm/s^2) would otherwise be fitted as a gravity.
      if (e != NumberError::kNone || !(g >= kMinGravity && g <= kMaxGravity)) {
        return ErrorAt(
            name,
            line_number,
            CharColumn(comment, value.data()),
            "metadata 'gravity': " +
                (e != NumberError::kNone
                     ? NumberMessage(e, value)
                     : Quote(value) + " is outside [0.1, 100] m/s^2") +
                "; expected the gravity in m/s^2, e.g. 9.80665");
      }
      data.gravity = g;
    }
    file.metadata.emplace_back(std::string(key), std::string(value));
    return Status::Ok();
  };

  // --- Header -------------------------------------------------------------
  bool have_header = false;
  while (next_line()) {
    const Kind kind = classify(line);
    if (kind == Kind::kBlank) continue;
    if (kind == Kind::kComment) {
      IMUSYSID_RETURN_IF_ERROR(handle_comment(line));
      continue;
    }
    have_header = true;
    break;
  }
  if (!have_header) {
    return ErrorAt(
        name,
        std::max(line_number, 1),
        1,
        std::string(line_number == 0 ? "the file is empty"
                                     : "no header line: the file holds only "
                                       "comments or blank lines") +
            "; expected a header naming the columns " + RequiredList());
  }
  const int header_line = line_number;
  const std::string_view header_text = line;
  std::vector<Field> header_fields;
  SplitFields(line, &header_fields);
  std::vector<std::string> header;
  std::vector<int> roles;
  int role_column[kNumRoles];
  std::fill(role_column, role_column + kNumRoles, -1);
  for (std::size_t c = 0; c < header_fields.size(); ++c) {
    const Field& field = header_fields[c];
    const int col = CharColumn(line, field.start);
    if (field.text.empty()) {
      return ErrorAt(
          name,
          header_line,
          col,
          "header column " + std::to_string(c + 1) + " has an empty name");
    }
    double ignored;
    if (ParseNumber(field.text, &ignored) != NumberError::kNotANumber) {
      return ErrorAt(name,
                     header_line,
                     col,
                     "no header: the first non-comment line holds the number " +
                         Quote(field.text) +
                         " where a column name belongs; the first line must "
                         "name the columns " +
                         RequiredList());
    }
    for (std::size_t i = 0; i < header.size(); ++i) {
      if (header[i] == field.text) {
        return ErrorAt(
            name,
            header_line,
            col,
            "duplicate column name " + Quote(field.text) +
                " (first at column " +
                std::to_string(CharColumn(line, header_fields[i].start)) + ")");
      }
    }
    header.emplace_back(field.text);
    int role = kIgnored;
    for (int r = 0; r < kNumRoles; ++r) {
      if (field.text == kRoleNames[r]) role = r;
    }
    roles.push_back(role);
    if (role == kIgnored) {
      file.ignored_columns.emplace_back(field.text);
    } else {
      role_column[role] = static_cast<int>(c);
    }
  }
  std::vector<std::string> missing;
  for (int r = 0; r < kNumRequired; ++r) {
    if (role_column[r] < 0) missing.emplace_back(kRoleNames[r]);
  }
  if (!missing.empty()) {
    return ErrorAt(name,
                   header_line,
                   1,
                   "header " + Quote(header_text) + " is missing required " +
                       (missing.size() > 1 ? "columns " : "column ") +
                       JoinQuoted(missing) + "; required: " + RequiredList() +
                       " in any order");
  }

  std::vector<double>* dest_of_role[kNumRoles] = {&data.t_s,
                                                  &data.planar.f_x,
                                                  &data.planar.omega,
                                                  &data.planar.omega_dot,
                                                  &data.planar.v,
                                                  &data.planar.theta,
                                                  &data.planar.f_z};
  std::vector<std::vector<double>*> dest(header.size(), nullptr);
  for (std::size_t c = 0; c < header.size(); ++c) {
    if (roles[c] != kIgnored) dest[c] = dest_of_role[roles[c]];
  }
  // Reserved from the first rows' length rather than a count of the line
  // breaks, which was a second pass over the text.
  const std::size_t row_estimate = internal::EstimateRows(
      body.substr(std::min(pos, body.size())), header.size() + kNumRequired);
  for (std::vector<double>* d : dest) {
    if (d != nullptr) d->reserve(row_estimate);
  }

  // --- Rows ---------------------------------------------------------------
  const std::size_t t_column = static_cast<std::size_t>(role_column[kT]);
  const std::size_t num_columns = header.size();
  std::vector<double> row(num_columns);
  std::vector<Field> fields;
  // Views into `body`, which outlives the loop.
  std::string_view previous_t_text;
  int previous_t_line = 0;
  int last_row_line = header_line;
  const char* const body_end = body.data() + body.size();
  while (true) {
    Field t_field{};
    const char* const row_start = body.data() + std::min(pos, body.size());
    const char* row_end = ParsePlainRow(
        row_start, body_end, dest, t_column, row.data(), &t_field);
    if (row_end != nullptr) {
      for (std::size_t c = 0; c < num_columns; ++c) {
        if (dest[c] != nullptr) dest[c]->push_back(row[c]);
      }
      line = std::string_view(row_start,
                              static_cast<std::size_t>(row_end - row_start));
      if (row_end < body_end && *row_end == '\r') ++row_end;
      if (row_end < body_end && *row_end == '\n') ++row_end;
      pos = static_cast<std::size_t>(row_end - body.data());
      ++line_number;
    } else {
      if (!next_line()) break;
      const Kind kind = classify(line);
      if (kind != Kind::kContent) {
        if (kind == Kind::kComment) {
          IMUSYSID_RETURN_IF_ERROR(handle_comment(line));
        }
        continue;
      }
      SplitFields(line, &fields);
      if (fields.size() < header.size()) {
        return ErrorAt(name,
                       line_number,
                       CharColumn(line, line.data() + line.size()),
                       "row has " + std::to_string(fields.size()) +
                           " fields, expected " +
                           std::to_string(header.size()) +
                           " (the header's count); column '" +
                           header[fields.size()] + "' is missing");
      }
      if (fields.size() > header.size()) {
        const Field& extra = fields[header.size()];
        return ErrorAt(
            name,
            line_number,
            CharColumn(line, extra.start),
            "row has " + std::to_string(fields.size()) + " fields, expected " +
                std::to_string(header.size()) +
                " (the header's count); extra field " + Quote(extra.text));
      }
      for (std::size_t c = 0; c < header.size(); ++c) {
        if (dest[c] == nullptr) continue;
        double value = 0.0;
        const NumberError e = ParseNumber(fields[c].text, &value);
        if (e != NumberError::kNone) {
          return ErrorAt(name,
                         line_number,
                         CharColumn(line, fields[c].start),
                         "column '" + header[c] +
                             "': " + NumberMessage(e, fields[c].text));
        }
        dest[c]->push_back(value);
      }
      t_field = fields[t_column];
    }
    const std::size_t n = data.t_s.size();
    if (n >= 2 && !(data.t_s[n - 1] > data.t_s[n - 2])) {
      const bool equal = data.t_s[n - 1] == data.t_s[n - 2];
      return ErrorAt(name,
                     line_number,
                     CharColumn(line, t_field.start),
                     "column 't': time " + Quote(t_field.text) +
                         (equal ? " repeats the previous time "
                                : " is before the previous time ") +
                         Quote(previous_t_text) + " (line " +
                         std::to_string(previous_t_line) +
                         "); t must increase strictly");
    }
    previous_t_text = t_field.text;
    previous_t_line = line_number;
    last_row_line = line_number;
  }

  if (data.size() < kMinProblemSamples) {
    return ErrorAt(name,
                   last_row_line,
                   1,
                   "the problem has " + std::to_string(data.size()) +
                       " sample" + (data.size() == 1 ? "" : "s") +
                       ", fewer than the " +
                       std::to_string(kMinProblemSamples) + " the fit needs");
  }
  // Everything above makes this hold; it is the contract CreateModel checks.
  IMUSYSID_RETURN_IF_ERROR(data.Validate());
  return file;
}

StatusOr<ProblemFile> ReadProblemCsv(const std::string& path) {
  StatusOr<std::string> text = ReadFileToString(path);
  if (!text.ok()) return text.status();
  return ParseProblemCsv(*text, path);
}

}  // namespace imusysid
