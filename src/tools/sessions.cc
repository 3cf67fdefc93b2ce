#include "src/tools/sessions.h"

#include <cstdlib>
#include <string>
#include <vector>

namespace imusysid {
namespace {

struct Line {
  std::size_t begin = 0;  // offset of its first byte
  std::size_t end = 0;    // one past its '\n' (or the text's end)
  std::size_t number = 0;
};

std::vector<Line> SplitLines(std::string_view text) {
  std::vector<Line> lines;
  std::size_t start = 0;
  std::size_t number = 1;
  while (start < text.size()) {
    std::size_t nl = text.find('\n', start);
    const std::size_t end = nl == std::string_view::npos ? text.size() : nl + 1;
    lines.push_back({start, end, number++});
    start = end;
  }
  return lines;
}

bool IsCommentOrBlank(std::string_view line) {
  for (char c : line) {
    if (c == '#') return true;
    if (c != ' ' && c != '\t' && c != '\r' && c != '\n') return false;
  }
  return true;
}

// Index of column `t` in a header line, or -1.
int TimeColumn(std::string_view header) {
  int column = 0;
  std::size_t start = 0;
  while (start <= header.size()) {
    std::size_t comma = header.find(',', start);
    if (comma == std::string_view::npos) comma = header.size();
    std::string_view name = header.substr(start, comma - start);
    while (!name.empty() &&
           (name.back() == '\r' || name.back() == '\n' || name.back() == ' ')) {
      name.remove_suffix(1);
    }
    while (!name.empty() && name.front() == ' ') name.remove_prefix(1);
    if (name == "t") return column;
    ++column;
    start = comma + 1;
  }
  return -1;
}

// The time field of a data row, or false when it is not a plain number.
bool TimeOf(std::string_view line, int column, double* t) {
  std::size_t start = 0;
  for (int c = 0; c < column; ++c) {
    start = line.find(',', start);
    if (start == std::string_view::npos) return false;
    ++start;
  }
  std::size_t end = line.find_first_of(",\r\n", start);
  if (end == std::string_view::npos) end = line.size();
  const std::string field(line.substr(start, end - start));
  if (field.empty()) return false;
  char* stop = nullptr;
  *t = std::strtod(field.c_str(), &stop);
  return stop == field.c_str() + field.size();
}

}  // namespace

OrderedPiece LongestOrderedCsvPiece(std::string_view text,
                                    const std::string& name) {
  OrderedPiece out;
  out.text = std::string(text);
  const std::vector<Line> lines = SplitLines(text);
  std::size_t header = lines.size();
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const std::string_view line =
        text.substr(lines[i].begin, lines[i].end - lines[i].begin);
    if (!IsCommentOrBlank(line)) {
      header = i;
      break;
    }
  }
  if (header >= lines.size()) return out;
  const int column = TimeColumn(text.substr(
      lines[header].begin, lines[header].end - lines[header].begin));
  if (column < 0) return out;
  // Pieces: runs of rows whose time increases; a row that is not a plain
  // number leaves everything to the reader.
  struct Piece {
    std::size_t first = 0, last = 0;  // line indices, inclusive
  };
  std::vector<Piece> pieces;
  double previous = 0.0;
  for (std::size_t i = header + 1; i < lines.size(); ++i) {
    const std::string_view line =
        text.substr(lines[i].begin, lines[i].end - lines[i].begin);
    if (IsCommentOrBlank(line)) continue;
    double t = 0.0;
    if (!TimeOf(line, column, &t)) return out;
    if (pieces.empty() || !(t > previous)) {
      pieces.push_back({i, i});
    } else {
      pieces.back().last = i;
    }
    previous = t;
  }
  if (pieces.size() <= 1) return out;
  std::size_t best = 0;
  for (std::size_t p = 1; p < pieces.size(); ++p) {
    if (pieces[p].last - pieces[p].first >
        pieces[best].last - pieces[best].first) {
      best = p;
    }
  }
  const Piece& use = pieces[best];
  out.text = std::string(text.substr(0, lines[header].end));
  out.text += text.substr(lines[use.first].begin,
                          lines[use.last].end - lines[use.first].begin);
  out.note = name + ": time goes back " + std::to_string(pieces.size() - 1) +
             " time" + (pieces.size() > 2 ? "s" : "") + " (first at line " +
             std::to_string(lines[pieces[1].first].number) +
             "): the file holds " + std::to_string(pieces.size()) +
             " recordings; using the longest, lines " +
             std::to_string(lines[use.first].number) + "-" +
             std::to_string(lines[use.last].number) + ", and leaving the rest";
  return out;
}

}  // namespace imusysid
