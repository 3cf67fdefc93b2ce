// HTML for the report pages: text escaped for HTML and result tables, shared
// by the fit figures' index.html, the bench's and the 3-D report page, so
// every page states its numbers as text beside its figures.

#ifndef IMUSYSID_SRC_REPORT_HTML_H_
#define IMUSYSID_SRC_REPORT_HTML_H_

#include <string>
#include <utility>
#include <vector>

namespace imusysid {
namespace report {

// `text` with <, >, & and " replaced by entities, control bytes other than
// tab and line ends and invalid UTF-8 as \xNN text (EscapeForMarkup): valid
// UTF-8 for an element's text or a double-quoted attribute (the pages quote
// every attribute with ").
std::string HtmlEscape(const std::string& text);

// One cell: the text shown and, when not empty, the exact value it rounds
// (a data-value attribute, full precision, for scripts and tests that read
// the page).
struct HtmlCell {
  HtmlCell() = default;
  HtmlCell(std::string shown) : text(std::move(shown)) {}  // NOLINT: implicit
  HtmlCell(const char* shown) : text(shown) {}             // NOLINT: implicit
  HtmlCell(std::string shown, std::string exact)
      : text(std::move(shown)), value(std::move(exact)) {}
  std::string text;
  std::string value;
};

// A table with a caption, one header row and rows of cells (plain text,
// escaped when written). `id` (may be empty) names the <table> element.
struct HtmlTable {
  std::string id;
  std::string caption;
  std::vector<std::string> header;
  std::vector<std::vector<HtmlCell>> rows;
};

// The table as HTML: <table> with <caption>, <thead> and <tbody>.
std::string HtmlTableToString(const HtmlTable& table);

// The style sheet the pages share (inside a <style> element).
const char* HtmlStyle();

}  // namespace report
}  // namespace imusysid

#endif  // IMUSYSID_SRC_REPORT_HTML_H_
