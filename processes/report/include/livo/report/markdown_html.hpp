// Markdown to HTML for the report: the subset report.md is written in. Blocks: ATX headings (an id
// from their text), paragraphs, pipe tables (column alignment from the separator row; a header row
// of empty cells, as report.md's key-value tables have, is left out), bullet and
// numbered lists (nested by indentation, tight or loose), fenced code blocks, block quotes,
// horizontal rules. Inline: code spans, **strong** and *emphasis* (also with _, not inside words),
// links, images, <http...> autolinks, backslash escapes. Everything else is text: raw HTML is
// escaped, never passed through, and javascript: links are dropped.
#pragma once

#include <functional>
#include <string>

#include "livo/text_format.hpp"  // escapeMarkup

namespace livo::report {

struct MarkdownHtmlOptions {
  /// What an image's source becomes in the page (a data: URI of the file, say); an empty answer
  /// shows the image's text and source instead. Not set: the source as written.
  std::function<std::string(const std::string& source)> image_source;
};

std::string markdownToHtml(const std::string& markdown, const MarkdownHtmlOptions& options = {});

/// One line or paragraph of inline markdown.
std::string inlineMarkdownToHtml(const std::string& text, const MarkdownHtmlOptions& options = {});

/// A heading's id: its text in lower case, letters, digits, '-' and '_' kept, spaces as '-', the
/// rest dropped ("Where the estimate was weak" -> "where-the-estimate-was-weak").
std::string headingId(const std::string& text);

}  // namespace livo::report
