// Writing rendered images: 8-bit PNG and float PFM. Files are written to a temporary name and
// renamed, so a failure never leaves a partial output behind.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace gi {

struct ImageRGBA8 {
  int width = 0, height = 0;
  std::vector<uint8_t> pixels;  // width*height*4, row 0 at the top
};

struct ImageRGBA32F {
  int width = 0, height = 0;
  std::vector<float> pixels;  // width*height*4, row 0 at the top
};

void writePng(const std::string& path, const ImageRGBA8& image);
// Every output replaces only a regular file (or nothing): a device, FIFO, socket or folder at
// `path` (followed through symbolic links) is a gi::Error(FileNotFound) naming it, never
// replaced by a rename. The writers check it before they commit; apps check it before any work.
void checkReplaceableOutput(const std::string& path);
// Portable float map (3 channels, little-endian, bottom-to-top rows as the format requires).
void writePfm(const std::string& path, const ImageRGBA32F& image);
ImageRGBA32F readPfm(const std::string& path);
ImageRGBA8 readPng(const std::string& path);

float halfToFloat(uint16_t h);

}  // namespace gi
