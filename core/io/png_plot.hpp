#pragma once
// Minimal line plots saved as PNG, so `frostmpm` can draw its own figures without Python or
// image libraries. The encoder uses uncompressed deflate blocks: files are larger than zlib's,
// but plots are small and this keeps the core free of a zlib dependency.
#include <string>
#include <vector>

namespace frostmpm {

/// One line of a plot. Non-finite points are skipped and break the line.
struct PlotSeries {
  std::string label;  ///< shown in the legend
  std::vector<double> x, y;
};

/// One sub-plot (axes) of a figure.
struct PlotPanel {
  std::string title, x_label, y_label;
  std::vector<PlotSeries> series;
  bool log_y = false;  ///< log10 y axis (values <= 0 skipped)
};

/// Panels are stacked vertically and share the figure width.
struct PlotFigure {
  std::string title;
  std::vector<PlotPanel> panels;
  int width = 900;
  int height_per_panel = 320;
};

/// Renders the figure (panels stacked vertically) to an RGB PNG. Throws std::runtime_error if the
/// file cannot be written. Text is printable ASCII; other characters are drawn as '?'.
void write_png_plot(const std::string& path, const PlotFigure& figure);

/// Lower-level: encodes an RGB8 image (row-major, 3 bytes per pixel) as PNG. The file is written
/// to `path + ".tmp"` and renamed, so readers never see a half-written image. Throws
/// std::invalid_argument if the size does not match `rgb`, std::runtime_error on I/O failure.
void write_png_rgb(const std::string& path, int width, int height, const std::vector<unsigned char>& rgb);

}  // namespace frostmpm
