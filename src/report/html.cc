#include "src/report/html.h"

#include <sstream>

#include "src/tools/safe_text.h"

namespace imusysid {
namespace report {

std::string HtmlEscape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  // A file name or log string may hold control bytes or bytes that are
  // not UTF-8: escaped first (\xNN), so the page stays valid UTF-8 and XML
  // text that a browser accepts.
  for (char c : EscapeForMarkup(text, /*keep_line_breaks=*/true)) {
    switch (c) {
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '&':
        out += "&amp;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string HtmlTableToString(const HtmlTable& table) {
  std::ostringstream html;
  html << "<table";
  if (!table.id.empty()) html << " id=\"" << HtmlEscape(table.id) << "\"";
  html << ">\n";
  if (!table.caption.empty()) {
    html << "<caption>" << HtmlEscape(table.caption) << "</caption>\n";
  }
  html << "<thead><tr>";
  for (const std::string& h : table.header) {
    html << "<th>" << HtmlEscape(h) << "</th>";
  }
  html << "</tr></thead>\n<tbody>\n";
  for (const auto& row : table.rows) {
    html << "<tr>";
    for (const HtmlCell& cell : row) {
      html << "<td";
      if (!cell.value.empty()) {
        html << " data-value=\"" << HtmlEscape(cell.value) << "\"";
      }
      html << ">" << HtmlEscape(cell.text) << "</td>";
    }
    html << "</tr>\n";
  }
  html << "</tbody>\n</table>\n";
  return html.str();
}

const char* HtmlStyle() {
  return "body{font-family:sans-serif;max-width:1040px;margin:auto;"
         "padding:0 1em}figure{margin:2em 0}img{max-width:100%}"
         "figcaption{color:#333}table{border-collapse:collapse;margin:1em 0;"
         "font-size:14px}caption{text-align:left;font-weight:bold;"
         "padding:.3em 0}th,td{border:1px solid #ccc;padding:.25em .5em;"
         "text-align:left;vertical-align:top}th{background:#f2f2f2}"
         "td[data-value]{text-align:right;font-variant-numeric:tabular-nums}"
         "pre{background:#f6f6f6;padding:.6em;overflow-x:auto}"
         ".kept{color:#176317}.dropped{color:#8a4b00}"
         ".withheld{color:#a00000}";
}

}  // namespace report
}  // namespace imusysid
