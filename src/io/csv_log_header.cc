// The CSV log reader's comments, header line and column binding
// (src/io/csv_log_header.h).

#include "src/io/csv_log_header.h"

#include <algorithm>
#include <string>
#include <string_view>
#include <vector>

#include "imusysid/log.h"
#include "src/io/csv_text.h"

namespace imusysid {
namespace internal {
namespace {

std::string JoinQuotedColumnNames(const std::vector<std::string>& names) {
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i > 0) out += ", ";
    out += "'" + names[i] + "'";
  }
  return out;
}

}  // namespace

Status CsvCommentHandler::Handle(std::string_view comment, int line_number) {
  std::string_view key, value;
  if (!ParseMetadata(comment, &key, &value)) return Status::Ok();
  if (key == "frame") {
    StatusOr<Frame> frame = FrameFromString(value);
    if (!frame.ok()) {
      return ErrorAt(name_,
                     line_number,
                     CharColumn(comment, value.data()),
                     "metadata 'frame': " + frame.status().message());
    }
    if (frame_seen_ && *frame != file_frame_) {
      return ErrorAt(name_,
                     line_number,
                     CharColumn(comment, value.data()),
                     "metadata 'frame': " + Quote(value) +
                         " contradicts 'frame: " + FrameToString(file_frame_) +
                         "' on line " + std::to_string(frame_line_));
    }
    frame_seen_ = true;
    file_frame_ = *frame;
    frame_line_ = line_number;
  }
  log_->metadata.emplace_back(std::string(key), std::string(value));
  return Status::Ok();
}

StatusOr<std::string_view> FindCsvHeaderLine(LineReader* reader,
                                             const std::string& name,
                                             CsvCommentHandler* comments) {
  std::string_view line;
  while (reader->Next(&line)) {
    const LineKind kind = Classify(line);
    if (kind == LineKind::kBlank) continue;
    if (kind == LineKind::kComment) {
      IMUSYSID_RETURN_IF_ERROR(comments->Handle(line, reader->line_number()));
      continue;
    }
    return line;
  }
  if (reader->line_number() == 0) {
    return ErrorAt(name,
                   1,
                   1,
                   "the file is empty; expected a header line "
                   "naming the columns t,ax,ay,az,gx,gy,gz");
  }
  return ErrorAt(name,
                 reader->line_number(),
                 1,
                 "no header line: the file holds only comments or blank "
                 "lines; expected a header naming the columns "
                 "t,ax,ay,az,gx,gy,gz");
}

StatusOr<CsvHeader> SplitCsvHeader(std::string_view line,
                                   int line_number,
                                   const std::string& name) {
  CsvHeader header;
  header.line = line_number;
  header.text = line;
  const char* p = line.data();
  const char* const end = p + line.size();
  while (true) {
    const char* stop = p;
    while (stop < end && *stop != ',') ++stop;
    const std::string_view field =
        TrimBlanks(std::string_view(p, static_cast<size_t>(stop - p)));
    const char* field_start = p;
    while (field_start < stop && IsBlank(*field_start)) ++field_start;
    const int col = CharColumn(line, field_start);
    if (field.empty()) {
      return ErrorAt(name,
                     line_number,
                     col,
                     "header column " +
                         std::to_string(header.names.size() + 1) +
                         " has an empty name");
    }
    double ignored;
    const char* bad;
    if (ParseCsvNumber(
            field.data(), field.data() + field.size(), &ignored, &bad) !=
        nullptr) {
      return ErrorAt(name,
                     line_number,
                     col,
                     "no header: the first non-comment line holds the "
                     "number " +
                         Quote(field) +
                         " where a column name belongs; the first line "
                         "must name the columns t,ax,ay,az,gx,gy,gz");
    }
    for (std::size_t i = 0; i < header.names.size(); ++i) {
      if (header.names[i] == field) {
        return ErrorAt(name,
                       line_number,
                       col,
                       "duplicate column name " + Quote(field) +
                           " (first at column " +
                           std::to_string(header.columns[i]) + ")");
      }
    }
    header.names.emplace_back(field);
    header.columns.push_back(col);
    if (stop == end) break;
    p = stop + 1;
  }
  return header;
}

StatusOr<CsvColumnBinding> BindCsvColumns(const CsvHeader& header,
                                          const std::string& name,
                                          std::size_t row_estimate,
                                          FlightLog* log) {
  int required_index[kCsvRequiredColumns];
  std::vector<std::string> missing;
  for (int r = 0; r < kCsvRequiredColumns; ++r) {
    const auto it = std::find(
        header.names.begin(), header.names.end(), kCsvRequiredNames[r]);
    required_index[r] = it == header.names.end()
                            ? -1
                            : static_cast<int>(it - header.names.begin());
    if (it == header.names.end()) missing.emplace_back(kCsvRequiredNames[r]);
  }
  if (!missing.empty()) {
    return ErrorAt(
        name,
        header.line,
        1,
        "header " + Quote(header.text) + " is missing required column" +
            (missing.size() > 1 ? "s " : " ") + JoinQuotedColumnNames(missing) +
            "; required: t,ax,ay,az,gx,gy,gz in any order");
  }

  CsvColumnBinding binding;
  std::vector<double>* required_dest[kCsvRequiredColumns] = {
      &log->t_s, &log->ax, &log->ay, &log->az, &log->gx, &log->gy, &log->gz};
  std::vector<std::vector<double>*>& dest = binding.dest;
  dest.assign(header.names.size(), nullptr);
  for (int r = 0; r < kCsvRequiredColumns; ++r) {
    dest[static_cast<std::size_t>(required_index[r])] = required_dest[r];
  }
  const std::size_t num_extra = header.names.size() - kCsvRequiredColumns;
  log->extra.reserve(num_extra);
  for (std::size_t c = 0; c < header.names.size(); ++c) {
    if (dest[c] == nullptr) log->extra.push_back(Channel{header.names[c], {}});
  }
  // Pointers into log.extra are taken only after it stopped growing.
  for (std::size_t c = 0, e = 0; c < header.names.size(); ++c) {
    if (dest[c] == nullptr) dest[c] = &log->extra[e++].values;
  }
  for (std::vector<double>* d : dest) d->reserve(row_estimate);
  binding.empty_until_first.assign(header.names.size(), 0);
  for (std::size_t c = 0; c < header.names.size(); ++c) {
    for (const char* channel : kEstimatorChannels) {
      if (header.names[c] == channel) binding.empty_until_first[c] = 1;
    }
  }
  binding.t_column = static_cast<std::size_t>(required_index[0]);
  return binding;
}

}  // namespace internal
}  // namespace imusysid
