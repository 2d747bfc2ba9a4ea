// The PNG writer is checked by decoding its output with an independent minimal decoder (stored
// deflate blocks only, which is all the writer emits), and by matplotlib when it is installed.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <stdexcept>

#include "frostmpm/io/png_plot.hpp"
#include "test_support.hpp"

namespace {

using frostmpm::PlotFigure;
using frostmpm::PlotPanel;
using frostmpm::PlotSeries;
using Bytes = std::vector<unsigned char>;

Bytes read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::uint32_t be32(const Bytes& b, std::size_t pos) {
  return (std::uint32_t{b[pos]} << 24) | (std::uint32_t{b[pos + 1]} << 16) | (std::uint32_t{b[pos + 2]} << 8) |
         std::uint32_t{b[pos + 3]};
}

// Bit-at-a-time CRC-32, deliberately unlike the writer's table-driven one.
std::uint32_t crc32_bitwise(const unsigned char* data, std::size_t size) {
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < size; ++i) {
    c ^= data[i];
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
  }
  return ~c;
}

std::uint32_t adler32(const Bytes& data) {
  std::uint64_t a = 1, b = 0;
  for (unsigned char byte : data) {
    a = (a + byte) % 65521;
    b = (b + a) % 65521;
  }
  return static_cast<std::uint32_t>((b << 16) | a);
}

constexpr unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};

/// Part (1): signature, then IHDR with the expected width (big-endian bytes). Returns the height.
std::uint32_t check_header(const Bytes& file, std::uint32_t width) {
  REQUIRE(file.size() > 33);
  REQUIRE(std::equal(std::begin(kSignature), std::end(kSignature), file.begin()));
  REQUIRE(be32(file, 8) == 13);
  REQUIRE(std::string(file.begin() + 12, file.begin() + 16) == "IHDR");
  REQUIRE(be32(file, 16) == width);
  REQUIRE(file[24] == 8);  // bit depth
  REQUIRE(file[25] == 2);  // RGB
  return be32(file, 20);
}

struct DecodedPng {
  std::uint32_t width = 0, height = 0;
  Bytes rgb;
  int stored_blocks = 0;

  bool is_white(std::size_t x, std::size_t y) const {
    const std::size_t i = (y * width + x) * 3;
    return rgb[i] == 255 && rgb[i + 1] == 255 && rgb[i + 2] == 255;
  }
};

/// Part (2): full decode, failing the test on any checksum or structure error.
DecodedPng decode_png(const Bytes& file) {
  REQUIRE(file.size() >= 8);
  REQUIRE(std::equal(std::begin(kSignature), std::end(kSignature), file.begin()));
  DecodedPng png;
  Bytes zlib;
  bool seen_iend = false;
  for (std::size_t pos = 8; pos < file.size();) {
    REQUIRE_FALSE(seen_iend);  // nothing may follow IEND
    REQUIRE(pos + 12 <= file.size());
    const std::uint32_t length = be32(file, pos);
    REQUIRE(pos + 12 + length <= file.size());
    const std::string type(file.begin() + static_cast<std::ptrdiff_t>(pos + 4),
                           file.begin() + static_cast<std::ptrdiff_t>(pos + 8));
    INFO("chunk " << type << " at byte " << pos);
    REQUIRE(crc32_bitwise(&file[pos + 4], length + 4) == be32(file, pos + 8 + length));
    const auto data = file.begin() + static_cast<std::ptrdiff_t>(pos + 8);
    if (type == "IHDR") {
      REQUIRE(length == 13);
      png.width = be32(file, pos + 8);
      png.height = be32(file, pos + 12);
      REQUIRE(Bytes(data + 8, data + 13) == Bytes{8, 2, 0, 0, 0});
    } else if (type == "IDAT") {
      zlib.insert(zlib.end(), data, data + length);
    } else if (type == "IEND") {
      seen_iend = true;
    }
    pos += 12 + length;
  }
  REQUIRE(seen_iend);
  REQUIRE(png.width > 0);
  REQUIRE(png.height > 0);

  REQUIRE(zlib.size() >= 2 + 5 + 4);
  REQUIRE((zlib[0] & 0x0F) == 8);  // deflate
  REQUIRE((zlib[0] * 256 + zlib[1]) % 31 == 0);
  REQUIRE((zlib[1] & 0x20) == 0);  // no preset dictionary
  Bytes raw;
  std::size_t pos = 2;
  for (bool final_block = false; !final_block;) {
    REQUIRE(pos + 5 <= zlib.size());
    final_block = (zlib[pos] & 1) != 0;
    REQUIRE(((zlib[pos] >> 1) & 3) == 0);  // stored
    const unsigned len = zlib[pos + 1] | (zlib[pos + 2] << 8);
    const unsigned nlen = zlib[pos + 3] | (zlib[pos + 4] << 8);
    REQUIRE(len == (~nlen & 0xFFFFu));
    REQUIRE(pos + 5 + len <= zlib.size());
    raw.insert(raw.end(), zlib.begin() + static_cast<std::ptrdiff_t>(pos + 5),
               zlib.begin() + static_cast<std::ptrdiff_t>(pos + 5 + len));
    pos += 5 + len;
    ++png.stored_blocks;
  }
  REQUIRE(pos + 4 == zlib.size());
  REQUIRE(be32(zlib, pos) == adler32(raw));

  const std::size_t row_bytes = std::size_t{png.width} * 3;
  REQUIRE(raw.size() == (row_bytes + 1) * png.height);
  for (std::size_t y = 0; y < png.height; ++y) {
    const auto row = raw.begin() + static_cast<std::ptrdiff_t>(y * (row_bytes + 1));
    REQUIRE(*row == 0);  // filter "none": unfiltering is just dropping the byte
    png.rgb.insert(png.rgb.end(), row + 1, row + 1 + static_cast<std::ptrdiff_t>(row_bytes));
  }
  return png;
}

std::size_t count_pixels(const DecodedPng& png, bool (*predicate)(const unsigned char*)) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < png.rgb.size(); i += 3) n += predicate(&png.rgb[i]) ? 1 : 0;
  return n;
}
bool non_white(const unsigned char* p) { return p[0] != 255 || p[1] != 255 || p[2] != 255; }
bool coloured(const unsigned char* p) { return p[0] != p[1] || p[1] != p[2]; }  // axes and text are grey

/// Part (3): matplotlib reads the file with the right shape; skipped when unavailable.
void check_with_matplotlib(const frostmpm::test::TempDir& dir, const std::string& path, std::uint32_t width,
                           std::uint32_t height) {
  const std::string python = "/usr/bin/python3";
  const std::string env = "MPLCONFIGDIR='" + dir.file("mpl") + "' ";
  if (!std::filesystem::exists(python) ||
      frostmpm::test::run_command(env + python + " -c 'import matplotlib.image'").exit_code != 0) {
    WARN("matplotlib not available: skipped reading the PNG back with it");
    return;
  }
  const std::string script =
      "import sys, matplotlib.image as m; a = m.imread(sys.argv[1]); print(a.shape); "
      "sys.exit(0 if a.shape == (" + std::to_string(height) + ", " + std::to_string(width) +
      ", 3) and (a[0, 0] == 1).all() else 1)";
  const auto result = frostmpm::test::run_command(env + python + " -c '" + script + "' '" + path + "'");
  INFO(result.output);
  REQUIRE(result.exit_code == 0);
}

PlotSeries sampled(const std::string& label, int n, double (*f)(double)) {
  PlotSeries s{label, {}, {}};
  for (int i = 0; i < n; ++i) {
    s.x.push_back(i * 0.1);
    s.y.push_back(f(i * 0.1));
  }
  return s;
}

}  // namespace

TEST_CASE("write_png_rgb output decodes to the same pixels", "[png]") {
  frostmpm::test::TempDir dir;
  const std::string path = dir.file("image.png");
  // Wide enough to need several stored blocks (each holds at most 65535 bytes).
  const int width = GENERATE(3, 301);
  const int height = GENERATE(2, 150);
  Bytes rgb(static_cast<std::size_t>(width) * height * 3);
  for (std::size_t i = 0; i < rgb.size(); ++i) rgb[i] = static_cast<unsigned char>((i * 7 + i / 3) % 256);

  frostmpm::write_png_rgb(path, width, height, rgb);
  const Bytes file = read_bytes(path);
  REQUIRE(check_header(file, width) == static_cast<std::uint32_t>(height));
  const DecodedPng png = decode_png(file);
  REQUIRE(png.width == static_cast<std::uint32_t>(width));
  REQUIRE(png.height == static_cast<std::uint32_t>(height));
  REQUIRE(png.rgb == rgb);
  const std::size_t raw_size = (static_cast<std::size_t>(width) * 3 + 1) * height;
  REQUIRE(png.stored_blocks == static_cast<int>((raw_size + 65534) / 65535));
  REQUIRE_FALSE(std::filesystem::exists(path + ".tmp"));
}

TEST_CASE("write_png_rgb rejects bad buffers and unwritable paths", "[png]") {
  frostmpm::test::TempDir dir;
  REQUIRE_THROWS_AS(frostmpm::write_png_rgb(dir.file("a.png"), 2, 2, Bytes(11)), std::invalid_argument);
  REQUIRE_THROWS_AS(frostmpm::write_png_rgb(dir.file("a.png"), 0, 2, Bytes{}), std::invalid_argument);
  REQUIRE_THROWS_AS(frostmpm::write_png_rgb(dir.file("no/such/dir.png"), 1, 1, Bytes(3)), std::runtime_error);

  // Renaming onto a non-empty directory fails after the temporary file was written: it must not linger.
  const std::string blocked = dir.file("blocked.png");
  std::filesystem::create_directories(blocked + "/inside");
  REQUIRE_THROWS_AS(frostmpm::write_png_rgb(blocked, 1, 1, Bytes(3)), std::runtime_error);
  REQUIRE_FALSE(std::filesystem::exists(blocked + ".tmp"));
}

TEST_CASE("write_png_plot renders a figure that PNG readers accept", "[png]") {
  frostmpm::test::TempDir dir;
  const std::string path = dir.file("plot.png");

  PlotPanel lines{"Temperature at probes", "time [s]", "T [degC]", {}, false};
  lines.series.push_back(sampled("sin(t)", 100, [](double t) { return std::sin(t); }));
  lines.series.push_back(sampled("cos(t) - 0.5", 100, [](double t) { return std::cos(t) - 0.5; }));
  lines.series[1].y[40] = std::numeric_limits<double>::quiet_NaN();  // a gap in the line
  PlotPanel log{"Residual", "iteration", "|r|", {}, true};
  log.series.push_back(sampled("residual", 60, [](double t) { return std::pow(10.0, -t); }));
  log.series[0].y[5] = 0.0;  // not drawable on a log axis
  PlotFigure figure{"FrostMPM test figure", {lines, log}, 640, 300};

  frostmpm::write_png_plot(path, figure);
  REQUIRE_FALSE(std::filesystem::exists(path + ".tmp"));

  const Bytes file = read_bytes(path);
  const std::uint32_t height = check_header(file, 640);
  REQUIRE(height >= 2 * 300);  // panels, plus a strip for the figure title
  REQUIRE(height <= 2 * 300 + 100);
  const DecodedPng png = decode_png(file);
  REQUIRE(png.height == height);
  REQUIRE(png.rgb.size() == std::size_t{png.width} * png.height * 3);
  REQUIRE(png.is_white(0, 0));
  REQUIRE(png.is_white(png.width - 1, png.height - 1));
  const std::size_t ink = count_pixels(png, non_white);
  REQUIRE(ink > 2000);                      // axes, grid, text and lines
  REQUIRE(ink < png.rgb.size() / 3 / 2);    // still mostly background
  REQUIRE(count_pixels(png, coloured) > 500);  // the series themselves

  check_with_matplotlib(dir, path, png.width, png.height);
}

TEST_CASE("write_png_plot copes with degenerate data", "[png]") {
  frostmpm::test::TempDir dir;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  PlotFigure figure{"", {}, 300, 200};
  SECTION("no panels") {}
  SECTION("panel without series") { figure.panels.push_back({}); }
  SECTION("empty, constant, non-finite and mismatched series") {
    PlotPanel panel{"", "", "", {}, false};
    panel.series.push_back({"empty", {}, {}});
    panel.series.push_back({"constant", {1, 2, 3}, {5, 5, 5}});
    panel.series.push_back({"nan", {nan, 1}, {0, nan}});
    panel.series.push_back({"inf", {inf, -inf}, {1, 2}});
    panel.series.push_back({"short y", {0, 1, 2, 3}, {1, 2}});
    panel.series.push_back({"single point", {2}, {5}});
    figure.panels.push_back(panel);
  }
  SECTION("log axis without positive values") { figure.panels.push_back({"", "", "", {{"neg", {0, 1}, {-1, 0}}}, true}); }
  SECTION("log axis with one value") { figure.panels.push_back({"", "", "", {{"one", {3, 3}, {1e-7, 1e-7}}}, true}); }
  SECTION("tiny and huge magnitudes") {
    figure.panels.push_back({"", "", "", {{"tiny", {0, 1}, {1e-12, 3e-12}}}, false});
    figure.panels.push_back({"", "", "", {{"huge", {-1e300, 1e300}, {1e300, -1e300}}}, false});
    figure.panels.push_back({"", "", "", {{"near", {0, 1}, {1e9, 1e9 + 1e-6}}}, false});
  }

  const std::string path = dir.file("degenerate.png");
  frostmpm::write_png_plot(path, figure);
  const Bytes file = read_bytes(path);
  REQUIRE(check_header(file, 300) == std::max<std::uint32_t>(1, 200 * static_cast<std::uint32_t>(figure.panels.size())));
  const DecodedPng png = decode_png(file);
  REQUIRE(png.is_white(0, 0));
}
