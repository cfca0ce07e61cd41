// Markdown to HTML for report.html: each block and inline form report.md uses, the escaping that
// keeps a run's text from becoming markup, and a whole report.md-like page.
#include <gtest/gtest.h>

#include "livo/report/markdown_html.hpp"

using namespace livo::report;

TEST(MarkdownHtml, HeadingsGetIdsFromTheirText) {
  EXPECT_EQ(markdownToHtml("# Pipeline run\n"), "<h1 id=\"pipeline-run\">Pipeline run</h1>\n");
  EXPECT_EQ(markdownToHtml("## Where the estimate was weak ##\n"),
            "<h2 id=\"where-the-estimate-was-weak\">Where the estimate was weak</h2>\n");
  EXPECT_EQ(markdownToHtml("### `timing.json` *per* process"),
            "<h3 id=\"timingjson-per-process\"><code>timing.json</code> <em>per</em> process</h3>\n");
  // the same heading twice: distinct ids
  EXPECT_EQ(markdownToHtml("## A\n## A\n"), "<h2 id=\"a\">A</h2>\n<h2 id=\"a-2\">A</h2>\n");
  EXPECT_EQ(markdownToHtml("#hashtag"), "<p>#hashtag</p>\n");  // no space: not a heading
}

TEST(MarkdownHtml, ParagraphsJoinLinesAndEndAtBlankLines) {
  EXPECT_EQ(markdownToHtml("one\ntwo\n\nthree\n"), "<p>one\ntwo</p>\n<p>three</p>\n");
  EXPECT_EQ(markdownToHtml("text\n## heading\n"), "<p>text</p>\n<h2 id=\"heading\">heading</h2>\n");
  EXPECT_EQ(markdownToHtml("a\r\nb\r\n"), "<p>a\nb</p>\n");
  EXPECT_EQ(markdownToHtml(""), "");
  EXPECT_EQ(markdownToHtml("---\n"), "<hr>\n");
}

TEST(MarkdownHtml, TablesWithAlignmentAndInlineCells) {
  const std::string md =
      "| process | median ms | note |\n"
      "| --- | ---: | :---: |\n"
      "| lio | 4.25 | `ODOMETRY` |\n"
      "| vio | 7 | a \\| b |\n"
      "| loop |\n";
  EXPECT_EQ(markdownToHtml(md),
            "<table>\n<thead>\n"
            "<tr><th>process</th><th style=\"text-align:right\">median ms</th><th "
            "style=\"text-align:center\">note</th></tr>\n"
            "</thead>\n<tbody>\n"
            "<tr><td>lio</td><td style=\"text-align:right\">4.25</td><td "
            "style=\"text-align:center\"><code>ODOMETRY</code></td></tr>\n"
            "<tr><td>vio</td><td style=\"text-align:right\">7</td><td style=\"text-align:center\">a | b</td></tr>\n"
            "<tr><td>loop</td><td style=\"text-align:right\"></td><td style=\"text-align:center\"></td></tr>\n"
            "</tbody>\n</table>\n");
  // report.md's key-value table: its empty header row is left out
  EXPECT_EQ(markdownToHtml("| | |\n| --- | --- |\n| log | `x.lcmlog` |\n"),
            "<table>\n<tbody>\n<tr><td>log</td><td><code>x.lcmlog</code></td></tr>\n</tbody>\n</table>\n");
  // a pipe in a paragraph without a separator row is text
  EXPECT_EQ(markdownToHtml("a | b\n"), "<p>a | b</p>\n");
}

TEST(MarkdownHtml, ListsTightLooseNestedAndNumbered) {
  EXPECT_EQ(markdownToHtml("- one\n- two\n  continued\n"), "<ul>\n<li>one</li>\n<li>two\ncontinued</li>\n</ul>\n");
  EXPECT_EQ(markdownToHtml("- one\n\n- two\n"), "<ul>\n<li><p>one</p></li>\n<li><p>two</p></li>\n</ul>\n");
  EXPECT_EQ(markdownToHtml("- a\n  - a1\n  - a2\n- b\n"),
            "<ul>\n<li>a\n<ul>\n<li>a1</li>\n<li>a2</li>\n</ul></li>\n<li>b</li>\n</ul>\n");
  EXPECT_EQ(markdownToHtml("3. three\n4. four\n"), "<ol start=\"3\">\n<li>three</li>\n<li>four</li>\n</ol>\n");
  EXPECT_EQ(markdownToHtml("1. first\n- other\n"), "<ol>\n<li>first</li>\n</ol>\n<ul>\n<li>other</li>\n</ul>\n");
  // a list right after a paragraph line, and text after the list
  EXPECT_EQ(markdownToHtml("Notes:\n- x\n\nafter\n"), "<p>Notes:</p>\n<ul>\n<li>x</li>\n</ul>\n<p>after</p>\n");
}

TEST(MarkdownHtml, CodeBlocksAndSpansAreEscapedVerbatim) {
  EXPECT_EQ(markdownToHtml("```bash\nrun <x> && **y**\n  indented\n```\n"),
            "<pre><code class=\"language-bash\">run &lt;x&gt; &amp;&amp; **y**\n  indented\n</code></pre>\n");
  EXPECT_EQ(inlineMarkdownToHtml("`*_epoch<N>.*` and ``a ` b``"),
            "<code>*_epoch&lt;N&gt;.*</code> and <code>a ` b</code>");
  EXPECT_EQ(inlineMarkdownToHtml("an `unclosed span"), "an `unclosed span");
  EXPECT_EQ(markdownToHtml("```\nnever closed\n"), "<pre><code>never closed\n</code></pre>\n");
}

TEST(MarkdownHtml, EmphasisNotInsideWordsOrAroundSpaces) {
  EXPECT_EQ(inlineMarkdownToHtml("**Degenerate sweeps** (`x`): *none*"),
            "<strong>Degenerate sweeps</strong> (<code>x</code>): <em>none</em>");
  EXPECT_EQ(inlineMarkdownToHtml("__strong__ and _em_"), "<strong>strong</strong> and <em>em</em>");
  EXPECT_EQ(inlineMarkdownToHtml("num_residuals and snake_case_name"), "num_residuals and snake_case_name");
  EXPECT_EQ(inlineMarkdownToHtml("2 * 3 * 4"), "2 * 3 * 4");
  EXPECT_EQ(inlineMarkdownToHtml("*a **b** c*"), "<em>a <strong>b</strong> c</em>");
  EXPECT_EQ(inlineMarkdownToHtml("**unclosed"), "**unclosed");
  EXPECT_EQ(inlineMarkdownToHtml("\\*not em\\*"), "*not em*");
}

TEST(MarkdownHtml, LinksImagesAndAutolinks) {
  EXPECT_EQ(inlineMarkdownToHtml("see [the README](processes/report/README.md \"docs\")"),
            "see <a href=\"processes/report/README.md\" title=\"docs\">the README</a>");
  EXPECT_EQ(inlineMarkdownToHtml("[**bold** link](a_(b).md)"), "<a href=\"a_(b).md\"><strong>bold</strong> link</a>");
  EXPECT_EQ(inlineMarkdownToHtml("<https://lcm-proj.github.io/>"),
            "<a href=\"https://lcm-proj.github.io/\">https://lcm-proj.github.io/</a>");
  EXPECT_EQ(inlineMarkdownToHtml("[x](javascript:alert(1))"), "x");
  EXPECT_EQ(inlineMarkdownToHtml("[not a link] (x)"), "[not a link] (x)");
  EXPECT_EQ(inlineMarkdownToHtml("![odometry against ground truth](odometry.svg)"),
            "<img src=\"odometry.svg\" alt=\"odometry against ground truth\">");
  MarkdownHtmlOptions o;
  o.image_source = [](const std::string& src) {
    return src == "a.png" ? std::string("data:image/png;base64,QUJD") : "";
  };
  EXPECT_EQ(inlineMarkdownToHtml("![A](a.png) ![B](b.png)", o),
            "<img src=\"data:image/png;base64,QUJD\" alt=\"A\"> <span class=\"missing-image\">[B: b.png]</span>");
}

TEST(MarkdownHtml, RawHtmlIsEscapedNeverPassedThrough) {
  EXPECT_EQ(markdownToHtml("<script>alert('x')</script> & \"q\"\n"),
            "<p>&lt;script&gt;alert(&#39;x&#39;)&lt;/script&gt; &amp; &quot;q&quot;</p>\n");
  EXPECT_EQ(markdownToHtml("> quoted *text*\n> more\n"),
            "<blockquote>\n<p>quoted <em>text</em>\nmore</p>\n</blockquote>\n");
  EXPECT_EQ(livo::escapeMarkup("a<b>&\"'"), "a&lt;b&gt;&amp;&quot;&#39;");
}

TEST(MarkdownHtml, AReportLikePage) {
  const std::string md =
      "# Pipeline run\n\n| | |\n| --- | --- |\n| log | `room.lcmlog` |\n\n## Accuracy\n\n"
      "No ground truth in the log: no accuracy figures.\n\n![odometry](odometry.svg)\n\n"
      "## Where the estimate was weak\n\n**Degenerate sweeps** (`ODOMETRY.degenerate`): 12 of 300 (4.0 %) in 2 "
      "stretches:\n\n"
      "| from s | to s | sweeps | least certain |\n| --- | --- | --- | --- |\n| 1.0 | 2.0 | 11 | along the direction "
      "of travel (body x) |\n\n"
      "**Images the VIO did not use**:\n\n- vio: none of 600.\n\n## Warnings\n\nNone.\n";
  const std::string html = markdownToHtml(md);
  for (const char* part :
       {"<h1 id=\"pipeline-run\">", "<td><code>room.lcmlog</code></td>", "<h2 id=\"accuracy\">",
        "<p><img src=\"odometry.svg\" alt=\"odometry\"></p>", "<h2 id=\"where-the-estimate-was-weak\">",
        "<p><strong>Degenerate sweeps</strong> (<code>ODOMETRY.degenerate</code>): 12 of 300",
        "<td>along the direction of travel (body x)</td>", "<li>vio: none of 600.</li>",
        "<h2 id=\"warnings\">Warnings</h2>\n<p>None.</p>"})
    EXPECT_NE(html.find(part), std::string::npos) << part << "\n" << html;
}
