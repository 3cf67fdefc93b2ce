#include "benchmarks/bench_internal.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <sstream>
#include <thread>
#include <vector>

#include "src/tools/format.h"

namespace imusysid {
namespace bench {
namespace internal {

void ParallelFor(std::size_t n,
                 int threads,
                 const std::function<void(std::size_t)>& task) {
  const int workers = std::max(
      1, std::min(threads, static_cast<int>(std::max<std::size_t>(n, 1))));
  std::atomic<std::size_t> next{0};
  auto work = [&]() {
    for (std::size_t i = next++; i < n; i = next++) task(i);
  };
  if (workers == 1) {
    work();
    return;
  }
  std::vector<std::thread> pool;
  for (int w = 0; w < workers; ++w) pool.emplace_back(work);
  for (auto& t : pool) t.join();
}

std::string FormatSeconds(double s) { return FormatFixed(s, 1) + " s"; }

std::string FixedCell(double v, int decimals) {
  return std::isfinite(v) ? FormatFixed(v, decimals) : "n/a";
}

std::string MarkdownTable(const std::vector<std::string>& header,
                          const std::vector<std::vector<std::string>>& rows) {
  std::ostringstream out;
  auto emit = [&](const std::vector<std::string>& row) {
    out << "|";
    for (std::size_t i = 0; i < header.size(); ++i) {
      out << " " << (i < row.size() ? row[i] : "") << " |";
    }
    out << "\n";
  };
  emit(header);
  out << "|";
  for (std::size_t i = 0; i < header.size(); ++i) out << " --- |";
  out << "\n";
  for (const auto& row : rows) emit(row);
  return out.str();
}

report::HtmlCell NumCell(double v, int decimals) {
  return std::isfinite(v)
             ? report::HtmlCell(FormatFixed(v, decimals), FormatShortest(v))
             : report::HtmlCell("n/a");
}

report::HtmlCell ScaledCell(double v, double scale, int decimals) {
  return std::isfinite(v) ? report::HtmlCell(FormatFixed(scale * v, decimals),
                                             FormatShortest(v))
                          : report::HtmlCell("n/a");
}

std::string HtmlTableMarkdown(const report::HtmlTable& t) {
  std::vector<std::vector<std::string>> rows;
  for (const auto& row : t.rows) {
    std::vector<std::string> cells;
    for (const report::HtmlCell& c : row) cells.push_back(c.text);
    rows.push_back(std::move(cells));
  }
  return MarkdownTable(t.header, rows);
}

std::string Truncate(const std::string& text, std::size_t n) {
  return text.size() <= n ? text : text.substr(0, n) + "…";
}

}  // namespace internal
}  // namespace bench
}  // namespace imusysid
