#pragma once
// Minimal PNG decoder for the screenshot test: 8-bit RGB or RGBA, non-interlaced (what
// Chromium writes). Inflates the IDAT stream with zlib and undoes the row filters
// (PNG spec clause 9). Throws std::runtime_error naming what it cannot read.
#include <zlib.h>

#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace eical::testing {

struct Image {
  std::uint32_t width = 0, height = 0;
  std::vector<std::uint8_t> rgb;  // width·height·3
};

inline Image decode_png(const std::string& file) {
  std::ifstream is(file, std::ios::binary);
  if (!is) throw std::runtime_error(file + ": cannot open");
  const std::vector<std::uint8_t> d{std::istreambuf_iterator<char>(is), std::istreambuf_iterator<char>()};
  static const std::uint8_t sig[8] = {137, 80, 78, 71, 13, 10, 26, 10};
  if (d.size() < 8 || !std::equal(sig, sig + 8, d.begin())) throw std::runtime_error(file + ": not a PNG");
  auto be32 = [&](std::size_t i) {
    return static_cast<std::uint32_t>(d[i]) << 24 | static_cast<std::uint32_t>(d[i + 1]) << 16 |
           static_cast<std::uint32_t>(d[i + 2]) << 8 | d[i + 3];
  };
  Image img;
  int channels = 0;
  std::vector<std::uint8_t> z;
  for (std::size_t i = 8; i + 8 <= d.size();) {
    const std::uint32_t len = be32(i);
    const std::string type(d.begin() + static_cast<std::ptrdiff_t>(i + 4),
                           d.begin() + static_cast<std::ptrdiff_t>(i + 8));
    if (i + 12 + len > d.size()) throw std::runtime_error(file + ": truncated chunk " + type);
    const std::size_t body = i + 8;
    if (type == "IHDR") {
      img.width = be32(body), img.height = be32(body + 4);
      const int depth = d[body + 8], color = d[body + 9], interlace = d[body + 12];
      if (depth != 8 || (color != 2 && color != 6) || interlace != 0)
        throw std::runtime_error(file + ": only 8-bit RGB/RGBA non-interlaced PNG is supported");
      channels = color == 2 ? 3 : 4;
    } else if (type == "IDAT") {
      z.insert(z.end(), d.begin() + static_cast<std::ptrdiff_t>(body),
               d.begin() + static_cast<std::ptrdiff_t>(body + len));
    } else if (type == "IEND") {
      break;
    }
    i += 12 + len;
  }
  if (channels == 0) throw std::runtime_error(file + ": no IHDR");
  const std::size_t stride = static_cast<std::size_t>(img.width) * static_cast<std::size_t>(channels);
  std::vector<std::uint8_t> raw((stride + 1) * img.height);
  uLongf raw_len = static_cast<uLongf>(raw.size());
  if (uncompress(raw.data(), &raw_len, z.data(), static_cast<uLong>(z.size())) != Z_OK || raw_len != raw.size())
    throw std::runtime_error(file + ": IDAT does not inflate to the image size");
  std::vector<std::uint8_t> cur(stride), prev(stride, 0);
  img.rgb.resize(static_cast<std::size_t>(img.width) * img.height * 3);
  for (std::uint32_t y = 0; y < img.height; ++y) {
    const std::uint8_t* row = &raw[y * (stride + 1)];
    const int filter = row[0];
    for (std::size_t x = 0; x < stride; ++x) {
      const int a = x >= static_cast<std::size_t>(channels) ? cur[x - static_cast<std::size_t>(channels)] : 0,
                b = prev[x],
                c = x >= static_cast<std::size_t>(channels) ? prev[x - static_cast<std::size_t>(channels)] : 0;
      int pred = 0;
      switch (filter) {
        case 0: pred = 0; break;
        case 1: pred = a; break;
        case 2: pred = b; break;
        case 3: pred = (a + b) / 2; break;
        case 4: {
          const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
          pred = pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
          break;
        }
        default: throw std::runtime_error(file + ": bad filter type in row " + std::to_string(y));
      }
      cur[x] = static_cast<std::uint8_t>(row[1 + x] + pred);
    }
    for (std::uint32_t x = 0; x < img.width; ++x)
      for (int k = 0; k < 3; ++k)
        img.rgb[(static_cast<std::size_t>(y) * img.width + x) * 3 + static_cast<std::size_t>(k)] =
            cur[x * static_cast<std::size_t>(channels) + static_cast<std::size_t>(k)];
    std::swap(cur, prev);
  }
  return img;
}

}  // namespace eical::testing
