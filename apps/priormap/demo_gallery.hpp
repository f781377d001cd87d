#pragma once
// The demo's gallery: one HTML page of sections, each entry with its figures, its key numbers
// and the exact commands that made them. Figures are linked by relative path, so the directory
// can be moved or served as it is; the page needs no network and runs no script.

#include <filesystem>
#include <string>
#include <vector>

namespace priormap::app {

struct GalleryFigure {
  std::string file;  // relative to the page
  std::string caption;
};

struct GalleryEntry {
  std::string title;
  std::vector<std::string> commands;
  std::vector<GalleryFigure> figures;
  std::vector<std::string> numbers;  // key numbers, one line each
  double seconds = 0.0;              // wall time of the commands
};

struct GallerySection {
  std::string heading;
  std::string intro;
  std::vector<GalleryEntry> entries;
};

/// Writes the page atomically.
void WriteGallery(const std::filesystem::path& page, const std::vector<GallerySection>& sections,
                  const std::string& footer);

}  // namespace priormap::app
