#include "demo_gallery.hpp"

#include <fmt/format.h>

#include <priormap/core/file_io.hpp>

namespace priormap::app {
namespace {

std::string HtmlEscape(const std::string& s) {
  std::string out;
  for (const char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
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

std::string Anchor(const std::string& heading) {
  std::string id;
  for (const char c : heading)
    if (std::isalnum(static_cast<unsigned char>(c)) != 0)
      id += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    else if (!id.empty() && id.back() != '-')
      id += '-';
  return id;
}

constexpr const char* kStyle =
    "body{font-family:system-ui,sans-serif;max-width:1500px;margin:1.5em auto;padding:0 1em;"
    "color:#222}h2{border-bottom:2px solid #ddd;padding-bottom:.2em;margin-top:2em}"
    ".entry{margin:1em 0 2.5em}.figures{display:flex;flex-wrap:wrap;gap:1em}"
    "figure{margin:0;flex:1 1 440px;max-width:720px}img{width:100%;border:1px solid #ccc}"
    "figcaption{font-size:90%;color:#444}ul.numbers{margin:.4em 0}"
    "pre{background:#f4f4f4;padding:.5em;overflow-x:auto;font-size:85%;white-space:pre-wrap}"
    "nav a{margin-right:1em}";

}  // namespace

void WriteGallery(const std::filesystem::path& page, const std::vector<GallerySection>& sections,
                  const std::string& footer) {
  std::string html = fmt::format(
      "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
      "<meta name=\"viewport\" content=\"width=device-width\"><title>priormap demo</title>"
      "<style>{}</style></head><body>\n<h1>priormap demo</h1>\n<nav>",
      kStyle);
  for (const GallerySection& section : sections)
    html +=
        fmt::format("<a href=\"#{}\">{}</a>", Anchor(section.heading), HtmlEscape(section.heading));
  html += "</nav>\n";
  for (const GallerySection& section : sections) {
    html += fmt::format("<h2 id=\"{}\">{}</h2>\n<p>{}</p>\n", Anchor(section.heading),
                        HtmlEscape(section.heading), HtmlEscape(section.intro));
    for (const GalleryEntry& entry : section.entries) {
      html += fmt::format("<div class=\"entry\"><h3>{}</h3>\n<ul class=\"numbers\">",
                          HtmlEscape(entry.title));
      for (const std::string& number : entry.numbers)
        html += fmt::format("<li>{}</li>", HtmlEscape(number));
      html += "</ul>\n<div class=\"figures\">";
      for (const GalleryFigure& figure : entry.figures)
        html += fmt::format(
            "<figure><a href=\"{0}\"><img src=\"{0}\" alt=\"{1}\"></a><figcaption>{1}</figcaption>"
            "</figure>\n",
            HtmlEscape(figure.file), HtmlEscape(figure.caption));
      std::string commands;
      for (const std::string& command : entry.commands) commands += command + "\n";
      html += fmt::format("</div>\n<pre>{}</pre><p><small>{:.1f} s</small></p></div>\n",
                          HtmlEscape(commands), entry.seconds);
    }
  }
  html += fmt::format("<hr><p><small>{}</small></p></body></html>\n", HtmlEscape(footer));
  WriteTextFileAtomically(page, html);
}

}  // namespace priormap::app
