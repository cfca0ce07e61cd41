#include "livo/report/markdown_html.hpp"

#include <cctype>
#include <map>
#include <optional>
#include <regex>
#include <sstream>
#include <vector>

namespace livo::report {

namespace {

bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }
bool isPunct(char c) { return std::ispunct(static_cast<unsigned char>(c)) != 0; }
bool isAlnum(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) != 0 || (static_cast<unsigned char>(c) & 0x80);
}

std::string trim(const std::string& s) {
  size_t a = 0, b = s.size();
  while (a < b && isSpace(s[a])) ++a;
  while (b > a && isSpace(s[b - 1])) --b;
  return s.substr(a, b - a);
}

bool blank(const std::string& line) { return trim(line).empty(); }

int indentOf(const std::string& line) {
  int n = 0;
  for (char c : line) {
    if (c == ' ')
      ++n;
    else if (c == '\t')
      n += 4 - n % 4;
    else
      break;
  }
  return n;
}

// The line without its first `n` columns of indentation (tabs count to the next multiple of 4).
std::string dedent(const std::string& line, int n) {
  int col = 0;
  size_t i = 0;
  while (i < line.size() && col < n && (line[i] == ' ' || line[i] == '\t')) {
    col = line[i] == '\t' ? col + 4 - col % 4 : col + 1;
    ++i;
  }
  return std::string(static_cast<size_t>(std::max(0, col - n)), ' ') + line.substr(i);
}

bool safeUrl(const std::string& url) {
  std::string s;
  for (char c : url)
    if (!isSpace(c) && c != '\0') s += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s.rfind("javascript:", 0) != 0 && s.rfind("vbscript:", 0) != 0 && s.rfind("data:text/html", 0) != 0;
}

// ---- inline -------------------------------------------------------------------------------------

class InlineRenderer {
 public:
  explicit InlineRenderer(const MarkdownHtmlOptions& options) : options_(options) {}

  std::string render(const std::string& s) const {
    std::string out;
    size_t i = 0;
    while (i < s.size()) {
      const char c = s[i];
      if (c == '\\' && i + 1 < s.size() && isPunct(s[i + 1])) {
        out += escapeMarkup(std::string(1, s[i + 1]));
        i += 2;
      } else if (c == '`') {
        i = codeSpan(s, i, &out);
      } else if (c == '!' && i + 1 < s.size() && s[i + 1] == '[') {
        i = linkOrImage(s, i, true, &out);
      } else if (c == '[') {
        i = linkOrImage(s, i, false, &out);
      } else if (c == '<') {
        i = autolink(s, i, &out);
      } else if (c == '*' || c == '_') {
        i = emphasis(s, i, &out);
      } else {
        out += escapeMarkup(std::string(1, c));
        ++i;
      }
    }
    return out;
  }

  // Text without markup (for alt text and ids).
  static std::string plain(const std::string& s) {
    std::string out;
    for (size_t i = 0; i < s.size(); ++i) {
      if (s[i] == '\\' && i + 1 < s.size() && isPunct(s[i + 1]))
        out += s[++i];
      else if (s[i] != '`' && s[i] != '*')
        out += s[i];
    }
    return out;
  }

 private:
  const MarkdownHtmlOptions& options_;

  static size_t runLength(const std::string& s, size_t i) {
    size_t j = i;
    while (j < s.size() && s[j] == s[i]) ++j;
    return j - i;
  }

  // The end of the code span opening at i (just past its closing run), or npos.
  static size_t codeSpanEnd(const std::string& s, size_t i) {
    const size_t n = runLength(s, i);
    for (size_t j = s.find('`', i + n); j != std::string::npos; j = s.find('`', j)) {
      const size_t m = runLength(s, j);
      if (m == n) return j + m;
      j += m;
    }
    return std::string::npos;
  }

  size_t codeSpan(const std::string& s, size_t i, std::string* out) const {
    const size_t n = runLength(s, i), end = codeSpanEnd(s, i);
    if (end == std::string::npos) {
      *out += std::string(n, '`');
      return i + n;
    }
    std::string code = s.substr(i + n, end - n - (i + n));
    for (char& c : code)
      if (c == '\n') c = ' ';
    if (code.size() >= 2 && code.front() == ' ' && code.back() == ' ' && !blank(code))
      code = code.substr(1, code.size() - 2);
    *out += "<code>" + escapeMarkup(code) + "</code>";
    return end;
  }

  // s[i] is '[': the index of its matching ']' (brackets nest, code spans and escapes skipped), or npos.
  static size_t closingBracket(const std::string& s, size_t i) {
    int depth = 0;
    for (size_t j = i; j < s.size(); ++j) {
      if (s[j] == '\\')
        ++j;
      else if (s[j] == '`') {
        const size_t end = codeSpanEnd(s, j);
        if (end != std::string::npos) j = end - 1;
      } else if (s[j] == '[')
        ++depth;
      else if (s[j] == ']' && --depth == 0)
        return j;
    }
    return std::string::npos;
  }

  size_t linkOrImage(const std::string& s, size_t i, bool image, std::string* out) const {
    const size_t open = image ? i + 1 : i;
    const size_t close = closingBracket(s, open);
    if (close == std::string::npos || close + 1 >= s.size() || s[close + 1] != '(') {
      *out += image ? "!" : "[";
      return image ? i + 1 : i + 1;
    }
    // (destination "optional title"), parentheses in the destination balanced
    size_t j = close + 2;
    while (j < s.size() && s[j] == ' ') ++j;
    std::string dest;
    int depth = 0;
    bool angle = j < s.size() && s[j] == '<';
    if (angle) ++j;
    for (; j < s.size(); ++j) {
      const char c = s[j];
      if (angle ? c == '>' : (isSpace(c) || (c == ')' && depth == 0))) break;
      if (c == '\\' && j + 1 < s.size() && isPunct(s[j + 1])) {
        dest += s[++j];
        continue;
      }
      if (c == '(') ++depth;
      if (c == ')') --depth;
      dest += c;
    }
    if (angle && j < s.size()) ++j;
    while (j < s.size() && s[j] == ' ') ++j;
    std::string title;
    if (j < s.size() && (s[j] == '"' || s[j] == '\'')) {
      const size_t end = s.find(s[j], j + 1);
      if (end == std::string::npos) return fail(image, i, out);
      title = s.substr(j + 1, end - j - 1);
      j = end + 1;
      while (j < s.size() && s[j] == ' ') ++j;
    }
    if (j >= s.size() || s[j] != ')') return fail(image, i, out);
    const std::string text = s.substr(open + 1, close - open - 1);
    const std::string title_attr = title.empty() ? "" : " title=\"" + escapeMarkup(title) + "\"";
    if (image) {
      const std::string src = options_.image_source ? options_.image_source(dest) : dest;
      if (src.empty() || !safeUrl(src))
        *out += "<span class=\"missing-image\">[" + escapeMarkup(plain(text)) + ": " + escapeMarkup(dest) + "]</span>";
      else
        *out += "<img src=\"" + escapeMarkup(src) + "\" alt=\"" + escapeMarkup(plain(text)) + "\"" + title_attr + ">";
    } else if (!safeUrl(dest)) {
      *out += render(text);
    } else {
      *out += "<a href=\"" + escapeMarkup(dest) + "\"" + title_attr + ">" + render(text) + "</a>";
    }
    return j + 1;
  }

  static size_t fail(bool image, size_t i, std::string* out) {
    *out += image ? "!" : "[";
    return i + 1;
  }

  size_t autolink(const std::string& s, size_t i, std::string* out) const {
    static const std::regex url(R"(^<((?:https?|mailto|file):[^\s<>]*)>)", std::regex::icase);
    std::smatch m;
    const std::string rest = s.substr(i, std::min<size_t>(s.size() - i, 2048));
    if (std::regex_search(rest, m, url)) {
      *out += "<a href=\"" + escapeMarkup(m[1].str()) + "\">" + escapeMarkup(m[1].str()) + "</a>";
      return i + static_cast<size_t>(m.length(0));
    }
    *out += "&lt;";
    return i + 1;
  }

  // A delimiter run of * or _ at i: opens when followed by a non-space (an _ also not inside a
  // word); closes at the next run of the same character and the same length that follows a
  // non-space (an _ not followed by a letter or digit). Two characters: strong, one: emphasis.
  size_t emphasis(const std::string& s, size_t i, std::string* out) const {
    const char c = s[i];
    const size_t run = runLength(s, i);
    const bool word_before = i > 0 && isAlnum(s[i - 1]);
    const bool opens = i + run < s.size() && !isSpace(s[i + run]) && !(c == '_' && word_before);
    if (opens && run <= 2) {
      for (size_t n = run; n >= 1; --n) {
        const size_t close = closingRun(s, i + n, c, n);
        if (close != std::string::npos) {
          const char* tag = n == 2 ? "strong" : "em";
          *out += std::string("<") + tag + ">" + render(s.substr(i + n, close - i - n)) + "</" + tag + ">";
          return close + n;
        }
      }
    }
    *out += std::string(run, c);
    return i + run;
  }

  static size_t closingRun(const std::string& s, size_t from, char c, size_t n) {
    for (size_t j = from; j < s.size(); ++j) {
      if (s[j] == '\\') {
        ++j;
      } else if (s[j] == '`') {
        const size_t end = codeSpanEnd(s, j);
        if (end != std::string::npos) j = end - 1;
      } else if (s[j] == c) {
        const size_t m = runLength(s, j);
        const bool after_word = j + m < s.size() && isAlnum(s[j + m]);
        if (m == n && j > from && !isSpace(s[j - 1]) && !(c == '_' && after_word)) return j;
        j += m - 1;
      }
    }
    return std::string::npos;
  }
};

// ---- blocks -------------------------------------------------------------------------------------

const std::regex kHeading(R"(^ {0,3}(#{1,6})(?:[ \t]+(.*?))?(?:[ \t]+#+)?[ \t]*$)");
const std::regex kRule(R"(^ {0,3}(?:(?:\*[ \t]*){3,}|(?:-[ \t]*){3,}|(?:_[ \t]*){3,})$)");
const std::regex kFence(R"(^( {0,3})(`{3,}|~{3,})[ \t]*([^`\s]*)[^`]*$)");
// Prefixes only (matched against a line's first characters, the rest taken as it is): libstdc++'s
// regex recurses once per character matched, so a long line under ".*" could exhaust the stack.
const std::regex kListItem(R"(^( {0,3})([-*+]|\d{1,9}[.)])( {1,4}|\t|$))");
const std::regex kQuote(R"(^ {0,3}> ?)");
constexpr size_t kPrefix = 24;

// The line after a block quote's marker, if it has one.
std::optional<std::string> quoted(const std::string& line) {
  std::smatch m;
  const std::string prefix = line.substr(0, kPrefix);
  if (!std::regex_search(prefix, m, kQuote)) return std::nullopt;
  return line.substr(static_cast<size_t>(m.length(0)));
}
const std::regex kTableSeparator(R"(^ {0,3}\|?[ \t]*:?-+:?[ \t]*(\|[ \t]*:?-+:?[ \t]*)*\|?[ \t]*$)");

struct ListMarker {
  int indent = 0;  // columns before the marker
  bool ordered = false;
  char delimiter = '-';  // -, *, + or . )
  long start = 1;
  int content = 0;    // the column the item's content starts at
  std::string first;  // the first line's content
};

std::optional<ListMarker> listMarker(const std::string& line) {
  std::smatch m;
  const std::string prefix = line.substr(0, kPrefix);
  if (!std::regex_search(prefix, m, kListItem)) return std::nullopt;
  ListMarker k;
  k.indent = static_cast<int>(m[1].length());
  const std::string marker = m[2].str();
  k.ordered = std::isdigit(static_cast<unsigned char>(marker[0])) != 0;
  k.delimiter = marker.back();
  if (k.ordered) k.start = std::stol(marker.substr(0, marker.size() - 1));
  const int gap = m[3].str() == "\t" ? 1 : static_cast<int>(m[3].length());
  k.content = k.indent + static_cast<int>(marker.size()) + std::max(gap, 1);
  k.first = line.substr(static_cast<size_t>(m.length(0)));
  return k;
}

// GFM pipe-table cells: outer pipes dropped, split at pipes that are not escaped.
std::vector<std::string> tableCells(const std::string& line) {
  std::string s = trim(line);
  if (!s.empty() && s.front() == '|') s.erase(0, 1);
  if (!s.empty() && s.back() == '|' && (s.size() < 2 || s[s.size() - 2] != '\\')) s.pop_back();
  std::vector<std::string> cells(1);
  for (size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '\\' && i + 1 < s.size() && s[i + 1] == '|') {
      cells.back() += '|';
      ++i;
    } else if (s[i] == '|') {
      cells.emplace_back();
    } else {
      cells.back() += s[i];
    }
  }
  for (auto& c : cells) c = trim(c);
  return cells;
}

class BlockRenderer {
 public:
  explicit BlockRenderer(const MarkdownHtmlOptions& o) : inline_(o) {}

  std::string render(const std::vector<std::string>& lines, bool tight) {
    std::string out;
    size_t i = 0;
    while (i < lines.size()) {
      const std::string& line = lines[i];
      std::smatch m;
      if (blank(line)) {
        ++i;
      } else if (std::regex_match(line, m, kFence)) {
        i = fence(lines, i, m, &out);
      } else if (std::regex_match(line, m, kHeading)) {
        const std::string text = m[2].str();
        const std::string level = std::to_string(m[1].length());
        out += "<h" + level + " id=\"" + uniqueId(text) + "\">" + inline_.render(text) + "</h" + level + ">\n";
        ++i;
      } else if (std::regex_match(line, kRule)) {
        out += "<hr>\n";
        ++i;
      } else if (startsTable(lines, i)) {
        i = table(lines, i, &out);
      } else if (quoted(line)) {
        std::vector<std::string> inner;
        for (; i < lines.size() && quoted(lines[i]); ++i) inner.push_back(*quoted(lines[i]));
        out += "<blockquote>\n" + render(inner, false) + "</blockquote>\n";
      } else if (const auto marker = listMarker(line)) {
        i = list(lines, i, *marker, &out);
      } else {
        std::string text;
        for (; i < lines.size() && !blank(lines[i]) && (text.empty() || !interrupts(lines, i)); ++i)
          text += (text.empty() ? "" : "\n") + trim(lines[i]);
        const std::string html = inline_.render(text);
        out += tight ? html + "\n" : "<p>" + html + "</p>\n";
      }
    }
    return out;
  }

 private:
  InlineRenderer inline_;
  std::map<std::string, int> ids_;

  std::string uniqueId(const std::string& text) {
    std::string id = headingId(InlineRenderer::plain(text));
    if (id.empty()) id = "section";
    const int n = ++ids_[id];
    return n == 1 ? id : id + "-" + std::to_string(n);
  }

  static bool startsTable(const std::vector<std::string>& lines, size_t i) {
    return i + 1 < lines.size() && lines[i].find('|') != std::string::npos &&
           std::regex_match(lines[i + 1], kTableSeparator) && lines[i + 1].find('-') != std::string::npos &&
           tableCells(lines[i]).size() == tableCells(lines[i + 1]).size();
  }

  // Whether line i starts another block (ending a paragraph).
  static bool interrupts(const std::vector<std::string>& lines, size_t i) {
    const std::string& l = lines[i];
    return std::regex_match(l, kFence) || std::regex_match(l, kHeading) || std::regex_match(l, kRule) ||
           quoted(l).has_value() || startsTable(lines, i) || listMarker(l).has_value();
  }

  size_t fence(const std::vector<std::string>& lines, size_t i, const std::smatch& m, std::string* out) {
    const int indent = static_cast<int>(m[1].length());
    const std::string marker = m[2].str(), language = m[3].str();
    std::string code;
    size_t j = i + 1;
    for (; j < lines.size(); ++j) {
      const std::string t = trim(lines[j]);
      if (t.size() >= marker.size() && t.find_first_not_of(marker[0]) == std::string::npos) break;
      code += escapeMarkup(dedent(lines[j], indent)) + "\n";
    }
    *out += "<pre><code" + (language.empty() ? std::string() : " class=\"language-" + escapeMarkup(language) + "\"") +
            ">" + code + "</code></pre>\n";
    return j < lines.size() ? j + 1 : j;
  }

  size_t table(const std::vector<std::string>& lines, size_t i, std::string* out) {
    const std::vector<std::string> header = tableCells(lines[i]);
    std::vector<std::string> align;
    for (const std::string& c : tableCells(lines[i + 1])) {
      const bool left = !c.empty() && c.front() == ':', right = !c.empty() && c.back() == ':';
      align.push_back(left && right ? "center" : right ? "right" : left ? "left" : "");
    }
    auto row = [&](const std::vector<std::string>& cells, const char* tag) {
      std::string r = "<tr>";
      for (size_t k = 0; k < header.size(); ++k) {
        r += std::string("<") + tag + (align[k].empty() ? "" : " style=\"text-align:" + align[k] + "\"") + ">";
        if (k < cells.size()) r += inline_.render(cells[k]);
        r += std::string("</") + tag + ">";
      }
      return r + "</tr>\n";
    };
    // a header of empty cells (report.md's key-value tables) is left out
    bool empty_header = true;
    for (const std::string& h : header) empty_header = empty_header && h.empty();
    *out += "<table>\n" + (empty_header ? std::string() : "<thead>\n" + row(header, "th") + "</thead>\n");
    size_t j = i + 2;
    std::string body;
    for (; j < lines.size() && !blank(lines[j]) && lines[j].find('|') != std::string::npos; ++j)
      body += row(tableCells(lines[j]), "td");
    if (!body.empty()) *out += "<tbody>\n" + body + "</tbody>\n";
    *out += "</table>\n";
    return j;
  }

  size_t list(const std::vector<std::string>& lines, size_t i, const ListMarker& first, std::string* out) {
    std::vector<std::vector<std::string>> items;
    bool loose = false, blank_pending = false;
    ListMarker marker = first;
    while (i < lines.size()) {
      std::vector<std::string> item{marker.first};
      ++i;
      bool blank_inside = false;
      for (; i < lines.size(); ++i) {
        const std::string& l = lines[i];
        if (blank(l)) {
          item.emplace_back();
          continue;
        }
        const bool after_blank = item.back().empty();
        if (indentOf(l) >= marker.content) {
          blank_inside = blank_inside || after_blank;
          item.push_back(dedent(l, marker.content));
        } else if (!after_blank && !interrupts(lines, i)) {
          item.push_back(trim(l));  // a lazy continuation of the paragraph
        } else {
          break;
        }
      }
      blank_pending = false;
      while (!item.empty() && item.back().empty()) {
        item.pop_back();
        blank_pending = true;
      }
      loose = loose || blank_inside;
      items.push_back(item);
      // the next item of the same list?
      const auto next = i < lines.size() ? listMarker(lines[i]) : std::nullopt;
      if (!next || next->ordered != first.ordered || next->delimiter != first.delimiter ||
          next->indent > first.indent + 3)
        break;
      loose = loose || blank_pending;
      marker = *next;
    }
    const char* tag = first.ordered ? "ol" : "ul";
    *out += std::string("<") + tag +
            (first.ordered && first.start != 1 ? " start=\"" + std::to_string(first.start) + "\"" : "") + ">\n";
    for (const auto& item : items) {
      std::string html = render(item, !loose);
      while (!html.empty() && html.back() == '\n') html.pop_back();
      *out += "<li>" + html + "</li>\n";
    }
    *out += std::string("</") + tag + ">\n";
    return i;
  }
};

}  // namespace

std::string headingId(const std::string& text) {
  std::string id;
  for (char c : trim(text)) {
    if (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_')
      id += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    else if (c == ' ')
      id += '-';
  }
  return id;
}

std::string inlineMarkdownToHtml(const std::string& text, const MarkdownHtmlOptions& options) {
  return InlineRenderer(options).render(text);
}

std::string markdownToHtml(const std::string& markdown, const MarkdownHtmlOptions& options) {
  std::vector<std::string> lines;
  std::istringstream in(markdown);
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    lines.push_back(line);
  }
  return BlockRenderer(options).render(lines, false);
}

}  // namespace livo::report
