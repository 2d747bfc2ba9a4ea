#include "frostmpm/io/png_plot.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <utility>
#include <stdexcept>
#include <string_view>

namespace frostmpm {

// ============================================================================================
// PNG encoding
// ============================================================================================
namespace {

constexpr std::array<std::uint32_t, 256> make_crc_table() {
  std::array<std::uint32_t, 256> table{};
  for (std::uint32_t n = 0; n < 256; ++n) {
    std::uint32_t c = n;
    for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    table[n] = c;
  }
  return table;
}
constexpr auto kCrcTable = make_crc_table();

std::uint32_t crc32(const unsigned char* data, std::size_t size) {
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < size; ++i) c = kCrcTable[(c ^ data[i]) & 0xFFu] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

std::uint32_t adler32(const std::vector<unsigned char>& data) {
  constexpr std::uint32_t kMod = 65521;
  std::uint32_t a = 1, b = 0;
  for (unsigned char byte : data) {
    a = (a + byte) % kMod;
    b = (b + a) % kMod;
  }
  return (b << 16) | a;
}

void put_u32_be(std::vector<unsigned char>& out, std::uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8) out.push_back(static_cast<unsigned char>(v >> shift));
}

void append_chunk(std::vector<unsigned char>& png, std::string_view type,
                  const std::vector<unsigned char>& data) {
  put_u32_be(png, static_cast<std::uint32_t>(data.size()));
  const std::size_t crc_start = png.size();  // the CRC covers type and data, not the length
  png.insert(png.end(), type.begin(), type.end());
  png.insert(png.end(), data.begin(), data.end());
  put_u32_be(png, crc32(png.data() + crc_start, png.size() - crc_start));
}

// zlib stream made of "stored" deflate blocks: no compression, so no zlib dependency.
std::vector<unsigned char> zlib_stored(const std::vector<unsigned char>& raw) {
  constexpr std::size_t kMaxBlock = 65535;  // LEN is 16 bits
  std::vector<unsigned char> out = {0x78, 0x01};  // deflate, 32K window; (0x78 * 256 + 0x01) % 31 == 0
  out.reserve(raw.size() + raw.size() / kMaxBlock * 5 + 16);
  std::size_t pos = 0;
  do {
    const std::size_t len = std::min(kMaxBlock, raw.size() - pos);
    const bool final_block = pos + len == raw.size();
    out.push_back(final_block ? 0x01 : 0x00);  // BFINAL bit, BTYPE = 00 (stored)
    const auto len16 = static_cast<std::uint16_t>(len);
    const auto nlen16 = static_cast<std::uint16_t>(~len16);
    for (std::uint16_t v : {len16, nlen16}) {  // little-endian, unlike the rest of PNG
      out.push_back(static_cast<unsigned char>(v & 0xFFu));
      out.push_back(static_cast<unsigned char>(v >> 8));
    }
    out.insert(out.end(), raw.begin() + static_cast<std::ptrdiff_t>(pos),
               raw.begin() + static_cast<std::ptrdiff_t>(pos + len));
    pos += len;
  } while (pos < raw.size());
  put_u32_be(out, adler32(raw));
  return out;
}

void write_file_atomically(const std::string& path, const std::vector<unsigned char>& bytes) {
  const std::string tmp = path + ".tmp";
  std::error_code ignored;
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error("cannot open '" + tmp + "' for writing");
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) {
      std::filesystem::remove(tmp, ignored);
      throw std::runtime_error("failed writing '" + tmp + "'");
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp, ignored);
    throw std::runtime_error("cannot rename '" + tmp + "' to '" + path + "': " + ec.message());
  }
}

}  // namespace

void write_png_rgb(const std::string& path, int width, int height, const std::vector<unsigned char>& rgb) {
  if (width <= 0 || height <= 0)
    throw std::invalid_argument("write_png_rgb: image size must be positive");
  const std::size_t row_bytes = static_cast<std::size_t>(width) * 3;
  if (rgb.size() != row_bytes * static_cast<std::size_t>(height))
    throw std::invalid_argument("write_png_rgb: buffer size does not match width * height * 3");

  std::vector<unsigned char> raw;  // each scanline is prefixed by its filter type (0 = none)
  raw.reserve((row_bytes + 1) * static_cast<std::size_t>(height));
  for (int y = 0; y < height; ++y) {
    raw.push_back(0);
    const auto row = rgb.begin() + static_cast<std::ptrdiff_t>(row_bytes * static_cast<std::size_t>(y));
    raw.insert(raw.end(), row, row + static_cast<std::ptrdiff_t>(row_bytes));
  }

  std::vector<unsigned char> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  std::vector<unsigned char> ihdr;
  put_u32_be(ihdr, static_cast<std::uint32_t>(width));
  put_u32_be(ihdr, static_cast<std::uint32_t>(height));
  ihdr.insert(ihdr.end(), {8, 2, 0, 0, 0});  // 8-bit, truecolour RGB, deflate, no filter set, no interlace
  append_chunk(png, "IHDR", ihdr);
  append_chunk(png, "IDAT", zlib_stored(raw));
  append_chunk(png, "IEND", {});
  write_file_atomically(path, png);
}

// ============================================================================================
// Raster and text
// ============================================================================================
namespace {

struct Rgb {
  unsigned char r, g, b;
};
constexpr Rgb kWhite{255, 255, 255};
constexpr Rgb kBlack{0, 0, 0};
constexpr Rgb kGrid{225, 225, 225};
constexpr Rgb kLegendBorder{160, 160, 160};
// matplotlib's "tab10": distinct, and familiar to anyone used to the Python plots.
constexpr std::array<Rgb, 10> kPalette = {{{31, 119, 180}, {255, 127, 14}, {44, 160, 44}, {214, 39, 40},
                                           {148, 103, 189}, {140, 86, 75}, {227, 119, 194}, {127, 127, 127},
                                           {188, 189, 34}, {23, 190, 207}}};

struct Rect {
  int x0, y0, x1, y1;  // inclusive
};

class Canvas {
 public:
  Canvas(int width, int height)
      : width_(width), height_(height), clip_{0, 0, width - 1, height - 1},
        pixels_(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3, 255) {}

  int width() const { return width_; }
  int height() const { return height_; }
  const std::vector<unsigned char>& pixels() const { return pixels_; }

  /// Drawing outside `clip` is dropped; lines use it to stay inside the axes box.
  void set_clip(const Rect& clip) {
    clip_ = {std::max(clip.x0, 0), std::max(clip.y0, 0), std::min(clip.x1, width_ - 1),
             std::min(clip.y1, height_ - 1)};
  }
  void reset_clip() { clip_ = {0, 0, width_ - 1, height_ - 1}; }

  void set(int x, int y, Rgb c) {
    if (x < clip_.x0 || x > clip_.x1 || y < clip_.y0 || y > clip_.y1) return;
    unsigned char* p = &pixels_[index(x, y)];
    p[0] = c.r;
    p[1] = c.g;
    p[2] = c.b;
  }

  void fill(const Rect& r, Rgb c) {
    for (int y = std::max(r.y0, clip_.y0); y <= std::min(r.y1, clip_.y1); ++y)
      for (int x = std::max(r.x0, clip_.x0); x <= std::min(r.x1, clip_.x1); ++x) set(x, y, c);
  }

  void outline(const Rect& r, Rgb c) {
    fill({r.x0, r.y0, r.x1, r.y0}, c);
    fill({r.x0, r.y1, r.x1, r.y1}, c);
    fill({r.x0, r.y0, r.x0, r.y1}, c);
    fill({r.x1, r.y0, r.x1, r.y1}, c);
  }

  /// Bresenham line stamped with a plus-shaped brush: 3 px wide when axis-aligned, ~2.4 px diagonal.
  void thick_line(int x0, int y0, int x1, int y1, Rgb c) {
    const int dx = std::abs(x1 - x0), sx = x0 < x1 ? 1 : -1;
    const int dy = -std::abs(y1 - y0), sy = y0 < y1 ? 1 : -1;
    int err = dx + dy;
    for (;;) {
      set(x0, y0, c);
      set(x0 - 1, y0, c);
      set(x0 + 1, y0, c);
      set(x0, y0 - 1, c);
      set(x0, y0 + 1, c);
      if (x0 == x1 && y0 == y1) break;
      const int e2 = 2 * err;
      if (e2 >= dy) {
        err += dy;
        x0 += sx;
      }
      if (e2 <= dx) {
        err += dx;
        y0 += sy;
      }
    }
  }

  /// Non-white pixels in `r`; used to put the legend where it hides the least.
  int ink(const Rect& r) const {
    int count = 0;
    for (int y = std::max(r.y0, 0); y <= std::min(r.y1, height_ - 1); ++y)
      for (int x = std::max(r.x0, 0); x <= std::min(r.x1, width_ - 1); ++x) {
        const unsigned char* p = &pixels_[index(x, y)];
        if (p[0] != 255 || p[1] != 255 || p[2] != 255) ++count;
      }
    return count;
  }

 private:
  std::size_t index(int x, int y) const {
    return (static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x)) * 3;
  }

  int width_, height_;
  Rect clip_;
  std::vector<unsigned char> pixels_;
};

// 5x7 bitmap font for ASCII 32..126, plus an eighth row for descenders (g j p q y , ;).
// Rows top first; bit 4 is the leftmost column.
constexpr int kGlyphW = 5, kGlyphH = 8, kCapH = 7, kAdvance = kGlyphW + 1;
constexpr unsigned char kFont[95][kGlyphH] = {
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00},  // ' '
    {0x04, 0x04, 0x04, 0x04, 0x04, 0x00, 0x04, 0x00},  // !
    {0x0A, 0x0A, 0x0A, 0x00, 0x00, 0x00, 0x00, 0x00},  // "
    {0x0A, 0x0A, 0x1F, 0x0A, 0x1F, 0x0A, 0x0A, 0x00},  // #
    {0x04, 0x0F, 0x14, 0x0E, 0x05, 0x1E, 0x04, 0x00},  // $
    {0x18, 0x19, 0x02, 0x04, 0x08, 0x13, 0x03, 0x00},  // %
    {0x0C, 0x12, 0x14, 0x08, 0x15, 0x12, 0x0D, 0x00},  // &
    {0x04, 0x04, 0x08, 0x00, 0x00, 0x00, 0x00, 0x00},  // '
    {0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02, 0x00},  // (
    {0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08, 0x00},  // )
    {0x00, 0x04, 0x15, 0x0E, 0x15, 0x04, 0x00, 0x00},  // *
    {0x00, 0x04, 0x04, 0x1F, 0x04, 0x04, 0x00, 0x00},  // +
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x04, 0x08},  // ,
    {0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00, 0x00},  // -
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C, 0x00},  // .
    {0x00, 0x01, 0x02, 0x04, 0x08, 0x10, 0x00, 0x00},  // /
    {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E, 0x00},  // 0
    {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E, 0x00},  // 1
    {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F, 0x00},  // 2
    {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E, 0x00},  // 3
    {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02, 0x00},  // 4
    {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E, 0x00},  // 5
    {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E, 0x00},  // 6
    {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08, 0x00},  // 7
    {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E, 0x00},  // 8
    {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C, 0x00},  // 9
    {0x00, 0x0C, 0x0C, 0x00, 0x0C, 0x0C, 0x00, 0x00},  // :
    {0x00, 0x00, 0x0C, 0x0C, 0x00, 0x0C, 0x04, 0x08},  // ;
    {0x02, 0x04, 0x08, 0x10, 0x08, 0x04, 0x02, 0x00},  // <
    {0x00, 0x00, 0x1F, 0x00, 0x1F, 0x00, 0x00, 0x00},  // =
    {0x08, 0x04, 0x02, 0x01, 0x02, 0x04, 0x08, 0x00},  // >
    {0x0E, 0x11, 0x01, 0x02, 0x04, 0x00, 0x04, 0x00},  // ?
    {0x0E, 0x11, 0x01, 0x0D, 0x15, 0x15, 0x0E, 0x00},  // @
    {0x0E, 0x11, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x00},  // A
    {0x1E, 0x11, 0x11, 0x1E, 0x11, 0x11, 0x1E, 0x00},  // B
    {0x0E, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0E, 0x00},  // C
    {0x1C, 0x12, 0x11, 0x11, 0x11, 0x12, 0x1C, 0x00},  // D
    {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x1F, 0x00},  // E
    {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x10, 0x00},  // F
    {0x0E, 0x11, 0x10, 0x17, 0x11, 0x11, 0x0F, 0x00},  // G
    {0x11, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11, 0x00},  // H
    {0x0E, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E, 0x00},  // I
    {0x07, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0C, 0x00},  // J
    {0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11, 0x00},  // K
    {0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1F, 0x00},  // L
    {0x11, 0x1B, 0x15, 0x15, 0x11, 0x11, 0x11, 0x00},  // M
    {0x11, 0x11, 0x19, 0x15, 0x13, 0x11, 0x11, 0x00},  // N
    {0x0E, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E, 0x00},  // O
    {0x1E, 0x11, 0x11, 0x1E, 0x10, 0x10, 0x10, 0x00},  // P
    {0x0E, 0x11, 0x11, 0x11, 0x15, 0x12, 0x0D, 0x00},  // Q
    {0x1E, 0x11, 0x11, 0x1E, 0x14, 0x12, 0x11, 0x00},  // R
    {0x0F, 0x10, 0x10, 0x0E, 0x01, 0x01, 0x1E, 0x00},  // S
    {0x1F, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04, 0x00},  // T
    {0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E, 0x00},  // U
    {0x11, 0x11, 0x11, 0x11, 0x11, 0x0A, 0x04, 0x00},  // V
    {0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0A, 0x00},  // W
    {0x11, 0x11, 0x0A, 0x04, 0x0A, 0x11, 0x11, 0x00},  // X
    {0x11, 0x11, 0x11, 0x0A, 0x04, 0x04, 0x04, 0x00},  // Y
    {0x1F, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1F, 0x00},  // Z
    {0x0E, 0x08, 0x08, 0x08, 0x08, 0x08, 0x0E, 0x00},  // [
    {0x00, 0x10, 0x08, 0x04, 0x02, 0x01, 0x00, 0x00},  // backslash
    {0x0E, 0x02, 0x02, 0x02, 0x02, 0x02, 0x0E, 0x00},  // ]
    {0x04, 0x0A, 0x11, 0x00, 0x00, 0x00, 0x00, 0x00},  // ^
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x1F, 0x00},  // _
    {0x08, 0x04, 0x02, 0x00, 0x00, 0x00, 0x00, 0x00},  // `
    {0x00, 0x00, 0x0E, 0x01, 0x0F, 0x11, 0x0F, 0x00},  // a
    {0x10, 0x10, 0x16, 0x19, 0x11, 0x11, 0x1E, 0x00},  // b
    {0x00, 0x00, 0x0E, 0x10, 0x10, 0x11, 0x0E, 0x00},  // c
    {0x01, 0x01, 0x0D, 0x13, 0x11, 0x11, 0x0F, 0x00},  // d
    {0x00, 0x00, 0x0E, 0x11, 0x1F, 0x10, 0x0E, 0x00},  // e
    {0x06, 0x09, 0x08, 0x1C, 0x08, 0x08, 0x08, 0x00},  // f
    {0x00, 0x00, 0x0F, 0x11, 0x11, 0x0F, 0x01, 0x0E},  // g
    {0x10, 0x10, 0x16, 0x19, 0x11, 0x11, 0x11, 0x00},  // h
    {0x04, 0x00, 0x0C, 0x04, 0x04, 0x04, 0x0E, 0x00},  // i
    {0x02, 0x00, 0x06, 0x02, 0x02, 0x02, 0x12, 0x0C},  // j
    {0x10, 0x10, 0x12, 0x14, 0x18, 0x14, 0x12, 0x00},  // k
    {0x0C, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E, 0x00},  // l
    {0x00, 0x00, 0x1A, 0x15, 0x15, 0x11, 0x11, 0x00},  // m
    {0x00, 0x00, 0x16, 0x19, 0x11, 0x11, 0x11, 0x00},  // n
    {0x00, 0x00, 0x0E, 0x11, 0x11, 0x11, 0x0E, 0x00},  // o
    {0x00, 0x00, 0x1E, 0x11, 0x11, 0x1E, 0x10, 0x10},  // p
    {0x00, 0x00, 0x0F, 0x11, 0x11, 0x0F, 0x01, 0x01},  // q
    {0x00, 0x00, 0x16, 0x19, 0x10, 0x10, 0x10, 0x00},  // r
    {0x00, 0x00, 0x0E, 0x10, 0x0E, 0x01, 0x1E, 0x00},  // s
    {0x08, 0x08, 0x1C, 0x08, 0x08, 0x09, 0x06, 0x00},  // t
    {0x00, 0x00, 0x11, 0x11, 0x11, 0x13, 0x0D, 0x00},  // u
    {0x00, 0x00, 0x11, 0x11, 0x11, 0x0A, 0x04, 0x00},  // v
    {0x00, 0x00, 0x11, 0x11, 0x15, 0x15, 0x0A, 0x00},  // w
    {0x00, 0x00, 0x11, 0x0A, 0x04, 0x0A, 0x11, 0x00},  // x
    {0x00, 0x00, 0x11, 0x11, 0x11, 0x0F, 0x01, 0x0E},  // y
    {0x00, 0x00, 0x1F, 0x02, 0x04, 0x08, 0x1F, 0x00},  // z
    {0x02, 0x04, 0x04, 0x08, 0x04, 0x04, 0x02, 0x00},  // {
    {0x04, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04, 0x00},  // |
    {0x08, 0x04, 0x04, 0x02, 0x04, 0x04, 0x08, 0x00},  // }
    {0x00, 0x00, 0x08, 0x15, 0x02, 0x00, 0x00, 0x00},  // ~
};

/// Printable-ASCII view of `text`: a UTF-8 sequence becomes one '?', not one per byte.
std::string printable(std::string_view text) {
  std::string out;
  for (char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if (c >= 0x80 && c < 0xC0) continue;  // UTF-8 continuation byte
    out += (c >= 32 && c <= 126) ? ch : '?';
  }
  return out;
}

constexpr int kTextScale = 2;  // 10x14 px capitals: about matplotlib's default size at 100 dpi
constexpr int kTitleScale = 3;
constexpr int text_height(int scale = kTextScale) { return kGlyphH * scale; }
/// Offset from the top of a text line to the middle of its capitals, for centring on a tick.
constexpr int text_middle(int scale = kTextScale) { return kCapH * scale / 2; }
int text_width(std::string_view text, int scale = kTextScale) {
  const int n = static_cast<int>(printable(text).size());
  return n == 0 ? 0 : (n * kAdvance - 1) * scale;
}

enum class Direction { horizontal, up };  // `up`: rotated 90 degrees, read bottom to top

/// Draws `text` with its bounding box's top-left corner at (x, y).
void draw_text(Canvas& canvas, std::string_view text, int x, int y, Rgb color, int scale = kTextScale,
               Direction direction = Direction::horizontal) {
  const std::string s = printable(text);
  const int length = text_width(s, scale);
  for (std::size_t i = 0; i < s.size(); ++i) {
    const auto& glyph = kFont[s[i] - 32];
    for (int row = 0; row < kGlyphH; ++row)
      for (int col = 0; col < kGlyphW; ++col) {
        if (!(glyph[row] & (0x10 >> col))) continue;
        const int u0 = (static_cast<int>(i) * kAdvance + col) * scale, v0 = row * scale;  // along, across
        for (int du = 0; du < scale; ++du)
          for (int dv = 0; dv < scale; ++dv) {
            const int u = u0 + du, v = v0 + dv;
            if (direction == Direction::horizontal)
              canvas.set(x + u, y + v, color);
            else
              canvas.set(x + v, y + length - 1 - u, color);
          }
      }
  }
}

// ============================================================================================
// Axes
// ============================================================================================

/// One axis in plotting coordinates (log10 of the value for a log axis).
struct Axis {
  double lo = 0, hi = 1;
  std::vector<double> ticks;
  std::vector<std::string> labels;

  /// Fraction 0..1 along the axis.
  double frac(double t) const { return (t - lo) / (hi - lo); }
};

/// 1, 2 or 5 times a power of ten, close to span / target.
double nice_step(double span, int target) {
  const double raw = span / std::max(target, 1);
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  const double f = raw / magnitude;
  return (f <= 1.0 ? 1.0 : f <= 2.0 ? 2.0 : f <= 5.0 ? 5.0 : 10.0) * magnitude;
}

std::string fixed(double value, int decimals) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
  return buffer;
}

/// Labels for linear ticks spaced by `step`: fixed-point with just enough decimals, or a shared
/// power of ten ("2.5e6") when fixed-point would be too long.
std::vector<std::string> linear_labels(const std::vector<double>& ticks, double step) {
  double largest = 0;
  for (double t : ticks) largest = std::max(largest, std::abs(t));
  const int step_exp = static_cast<int>(std::floor(std::log10(step) + 1e-9));
  const bool scientific = largest >= 1e6 || step_exp < -4;
  const int exp = scientific && largest > 0 ? static_cast<int>(std::floor(std::log10(largest) + 1e-9)) : 0;
  const int decimals = std::max(0, exp - step_exp);
  std::vector<std::string> labels;
  for (double t : ticks) {
    if (std::abs(t) < step * 1e-6) t = 0;  // no "-0"
    if (!scientific)
      labels.push_back(fixed(t, std::max(0, -step_exp)));
    else if (t == 0)
      labels.push_back("0");
    else
      labels.push_back(fixed(t / std::pow(10.0, exp), decimals) + "e" + std::to_string(exp));
  }
  return labels;
}

/// Axis covering [lo, hi] (plotting coordinates) with about `target` ticks on nice values;
/// the range is widened to whole ticks. Log axes tick at powers of ten only.
Axis make_axis(double lo, double hi, bool log, int target) {
  if (!(std::isfinite(lo) && std::isfinite(hi) && lo <= hi && std::isfinite(hi - lo))) {  // nothing usable
    lo = 0;
    hi = 1;
  }
  // A constant (or numerically constant) range still needs some extent to draw.
  if (hi - lo <= 1e-9 * std::max(std::abs(lo), std::abs(hi))) {
    const double pad = log ? 0.5 : (lo == 0 ? 1.0 : std::abs(lo) * 0.1);
    lo -= pad;
    hi += pad;
  }
  double step = nice_step(hi - lo, target);
  if (log) step = std::max(1.0, std::round(step));  // whole decades
  Axis axis;
  const double k0 = std::floor(lo / step + 1e-9), k1 = std::ceil(hi / step - 1e-9);
  if (!(std::isfinite(k0) && std::isfinite(k1) && k1 > k0) || k1 - k0 > 1000) return axis;  // degenerate
  axis.lo = k0 * step;
  axis.hi = k1 * step;
  for (int i = 0; i <= static_cast<int>(k1 - k0); ++i) axis.ticks.push_back((k0 + i) * step);
  if (!log) {
    axis.labels = linear_labels(axis.ticks, step);
  } else {
    for (double t : axis.ticks) {
      const int e = static_cast<int>(std::lround(t));
      axis.labels.push_back(e >= -3 && e <= 4 ? fixed(std::pow(10.0, e), std::max(0, -e))
                                              : "1e" + std::to_string(e));
    }
  }
  return axis;
}

/// A point is drawn only if finite (and positive on a log axis).
bool drawable(double x, double y, bool log_y) { return std::isfinite(x) && std::isfinite(y) && (!log_y || y > 0); }

std::size_t point_count(const PlotSeries& s) { return std::min(s.x.size(), s.y.size()); }

struct Range {
  double lo = std::numeric_limits<double>::infinity(), hi = -std::numeric_limits<double>::infinity();
  void add(double v) {
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
};

/// Extent of the drawable points in plotting coordinates.
std::pair<Range, Range> data_ranges(const PlotPanel& panel) {
  Range x, y;
  for (const auto& s : panel.series)
    for (std::size_t k = 0; k < point_count(s); ++k)
      if (drawable(s.x[k], s.y[k], panel.log_y)) {
        x.add(s.x[k]);
        y.add(panel.log_y ? std::log10(s.y[k]) : s.y[k]);
      }
  return {x, y};
}

// ============================================================================================
// Layout and drawing
// ============================================================================================
constexpr int kPad = 10;       // space around text blocks
constexpr int kTickLen = 5;
constexpr int kRightMargin = 36;  // room for half of the last x tick label

struct PanelFrame {
  int top;             // panel's first row in the image
  Rect plot;           // axes box
  Axis x_axis, y_axis;
};

int ticks_for(int pixels, int pixels_per_tick) { return std::clamp(pixels / pixels_per_tick, 2, 10); }

void draw_series(Canvas& canvas, const PlotPanel& panel, const PanelFrame& f) {
  const Rect& p = f.plot;
  auto to_pixel = [](double frac, int a, int b) {
    // Clamp before rounding so a wild value cannot overflow int; the clip hides it anyway.
    if (!std::isfinite(frac)) frac = -2.0;
    return static_cast<int>(std::lround(a + std::clamp(frac, -2.0, 3.0) * (b - a)));
  };
  canvas.set_clip({p.x0 + 1, p.y0 + 1, p.x1 - 1, p.y1 - 1});
  for (std::size_t s = 0; s < panel.series.size(); ++s) {
    const PlotSeries& series = panel.series[s];
    const Rgb color = kPalette[s % kPalette.size()];
    const std::size_t n = point_count(series);
    auto ok = [&](std::size_t i) { return i < n && drawable(series.x[i], series.y[i], panel.log_y); };
    auto px = [&](std::size_t i) { return to_pixel(f.x_axis.frac(series.x[i]), p.x0, p.x1); };
    auto py = [&](std::size_t i) {
      const double t = panel.log_y ? std::log10(series.y[i]) : series.y[i];
      return to_pixel(f.y_axis.frac(t), p.y1, p.y0);
    };
    for (std::size_t i = 0; i < n; ++i) {
      if (!ok(i)) continue;
      if (ok(i + 1)) {
        canvas.thick_line(px(i), py(i), px(i + 1), py(i + 1), color);
      } else if (i == 0 || !ok(i - 1)) {  // isolated point: no segment would show it
        canvas.fill({px(i) - 2, py(i) - 2, px(i) + 2, py(i) + 2}, color);
      }
    }
  }
  canvas.reset_clip();
}

void draw_axes(Canvas& canvas, const PlotPanel& panel, const PanelFrame& f) {
  const Rect& p = f.plot;
  const int th = text_height();
  for (std::size_t i = 0; i < f.x_axis.ticks.size(); ++i) {
    const int x = p.x0 + static_cast<int>(std::lround(f.x_axis.frac(f.x_axis.ticks[i]) * (p.x1 - p.x0)));
    canvas.fill({x, p.y0, x, p.y1}, kGrid);
    canvas.fill({x, p.y1, x, p.y1 + kTickLen}, kBlack);
    const std::string& label = f.x_axis.labels[i];
    draw_text(canvas, label, x - text_width(label) / 2, p.y1 + kTickLen + 4, kBlack);
  }
  for (std::size_t i = 0; i < f.y_axis.ticks.size(); ++i) {
    const int y = p.y1 - static_cast<int>(std::lround(f.y_axis.frac(f.y_axis.ticks[i]) * (p.y1 - p.y0)));
    canvas.fill({p.x0, y, p.x1, y}, kGrid);
    canvas.fill({p.x0 - kTickLen, y, p.x0, y}, kBlack);
    const std::string& label = f.y_axis.labels[i];
    draw_text(canvas, label, p.x0 - kTickLen - 4 - text_width(label), y - text_middle(), kBlack);
  }
  const int cx = (p.x0 + p.x1) / 2, cy = (p.y0 + p.y1) / 2;
  if (!panel.title.empty()) draw_text(canvas, panel.title, cx - text_width(panel.title) / 2, f.top + kPad, kBlack);
  if (!panel.x_label.empty())
    draw_text(canvas, panel.x_label, cx - text_width(panel.x_label) / 2, p.y1 + kTickLen + 4 + th + kPad, kBlack);
  if (!panel.y_label.empty())
    draw_text(canvas, panel.y_label, kPad, cy - text_width(panel.y_label) / 2, kBlack, kTextScale, Direction::up);
}

void draw_legend(Canvas& canvas, const PlotPanel& panel, const PanelFrame& f) {
  constexpr int kSample = 28, kGap = 6, kRow = text_height() + kGap, kInset = 8;
  int label_width = 0, rows = 0;
  for (const auto& s : panel.series) {
    if (s.label.empty()) continue;
    label_width = std::max(label_width, text_width(s.label));
    ++rows;
  }
  if (rows == 0) return;
  const int w = kPad + kSample + 8 + label_width + kPad, h = 2 * kGap + rows * kRow - kGap;
  const Rect& p = f.plot;
  // Like matplotlib's loc="best", but only the four corners: pick the one covering the least ink.
  const std::array<Rect, 4> corners = {{{p.x1 - kInset - w, p.y0 + kInset, p.x1 - kInset, p.y0 + kInset + h},
                                        {p.x0 + kInset, p.y0 + kInset, p.x0 + kInset + w, p.y0 + kInset + h},
                                        {p.x1 - kInset - w, p.y1 - kInset - h, p.x1 - kInset, p.y1 - kInset},
                                        {p.x0 + kInset, p.y1 - kInset - h, p.x0 + kInset + w, p.y1 - kInset}}};
  const Rect box = *std::min_element(corners.begin(), corners.end(),
                                     [&](const Rect& a, const Rect& b) { return canvas.ink(a) < canvas.ink(b); });
  canvas.fill(box, kWhite);
  canvas.outline(box, kLegendBorder);
  int y = box.y0 + kGap;
  for (std::size_t s = 0; s < panel.series.size(); ++s) {
    if (panel.series[s].label.empty()) continue;
    const int mid = y + text_middle();
    canvas.thick_line(box.x0 + kPad, mid, box.x0 + kPad + kSample, mid, kPalette[s % kPalette.size()]);
    draw_text(canvas, panel.series[s].label, box.x0 + kPad + kSample + 8, y, kBlack);
    y += kRow;
  }
}

}  // namespace

void write_png_plot(const std::string& path, const PlotFigure& figure) {
  // Too small to fit the text: enlarge rather than fail. Too large is surely a mistake.
  const int width = std::max(figure.width, 240);
  const int panel_h = std::max(figure.height_per_panel, 160);
  const int th = text_height();
  const int title_h = figure.title.empty() ? 0 : text_height(kTitleScale) + 2 * kPad;
  const long long total_h = title_h + static_cast<long long>(panel_h) * static_cast<long long>(figure.panels.size());
  if (width > 16384 || total_h > 16384) throw std::invalid_argument("write_png_plot: figure larger than 16384 px");
  const int height = std::max(static_cast<int>(total_h), 1);

  // Vertical layout first: it fixes the y ticks, whose widest label sets the shared left margin
  // (so the axes of stacked panels line up).
  std::vector<PanelFrame> frames;
  int label_w = 0;
  bool any_y_label = false;
  for (std::size_t i = 0; i < figure.panels.size(); ++i) {
    const PlotPanel& panel = figure.panels[i];
    PanelFrame f{};
    f.top = title_h + static_cast<int>(i) * panel_h;
    f.plot.y0 = f.top + kPad + (panel.title.empty() ? 0 : th + kPad);
    f.plot.y1 = f.top + panel_h - 1 - (kTickLen + 4 + th + kPad + (panel.x_label.empty() ? 0 : th + kPad));
    const Range y = data_ranges(panel).second;
    f.y_axis = make_axis(y.lo, y.hi, panel.log_y, ticks_for(f.plot.y1 - f.plot.y0, 45));
    for (const auto& label : f.y_axis.labels) label_w = std::max(label_w, text_width(label));
    any_y_label = any_y_label || !panel.y_label.empty();
    frames.push_back(f);
  }
  const int left = std::min(kPad + (any_y_label ? th + kPad : 0) + label_w + 4 + kTickLen, width / 2);

  Canvas canvas(width, height);
  if (!figure.title.empty())
    draw_text(canvas, figure.title, (width - text_width(figure.title, kTitleScale)) / 2, kPad, kBlack, kTitleScale);
  for (std::size_t i = 0; i < figure.panels.size(); ++i) {
    const PlotPanel& panel = figure.panels[i];
    PanelFrame& f = frames[i];
    f.plot.x0 = left;
    f.plot.x1 = width - 1 - kRightMargin;
    const Range x = data_ranges(panel).first;
    f.x_axis = make_axis(x.lo, x.hi, false, ticks_for(f.plot.x1 - f.plot.x0, 110));

    draw_axes(canvas, panel, f);  // grid first, so data is drawn over it
    draw_series(canvas, panel, f);
    canvas.outline(f.plot, kBlack);
    draw_legend(canvas, panel, f);
  }
  write_png_rgb(path, width, height, canvas.pixels());
}

}  // namespace frostmpm
