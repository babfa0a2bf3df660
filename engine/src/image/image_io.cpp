#include "gi/image_io.h"

#include <stb_image.h>
#include <stb_image_write.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>

#include "gi/errors.h"

namespace gi {

namespace {
// Moves a finished temporary file into place; removes it on failure.
void commitFile(const std::string& tmp, const std::string& path) {
  std::error_code ec;
  try {
    checkReplaceableOutput(path);
  } catch (...) {
    std::filesystem::remove(tmp, ec);
    throw;
  }
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw Error(ErrorKind::Output, path, "cannot write output file");
  }
}
// The temporary file beside `path`, whose missing folders are made first (an output named
// out/img.png in a fresh checkout).
std::string tempName(const std::string& path) {
  std::error_code ec;
  if (const auto folder = std::filesystem::path(path).parent_path(); !folder.empty())
    std::filesystem::create_directories(folder, ec);  // a failure shows when the file is opened
  return path + ".partial";
}
}  // namespace

void checkReplaceableOutput(const std::string& path) {
  std::error_code ec;
  const std::filesystem::file_status st = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(st) || std::filesystem::is_regular_file(st)) return;
  throw Error(ErrorKind::Output, path,
              std::filesystem::is_directory(st)
                  ? "output path is a folder, not a file"
                  : "output path is not a regular file (a device, FIFO or socket): it is never "
                    "replaced");
}

void writePng(const std::string& path, const ImageRGBA8& image) {
  const std::string tmp = tempName(path);
  errno = 0;
  if (!stbi_write_png(tmp.c_str(), image.width, image.height, 4, image.pixels.data(),
                      image.width * 4)) {
    const int err = errno;  // stb opens the file with fopen
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    throw Error(ErrorKind::Output, path,
                std::string("cannot write PNG: ") + (err ? std::strerror(err) : "write failed"));
  }
  commitFile(tmp, path);
}

ImageRGBA8 readPng(const std::string& path) {
  ImageRGBA8 img;
  int channels = 0;
  std::unique_ptr<stbi_uc, decltype(&stbi_image_free)> data(
      stbi_load(path.c_str(), &img.width, &img.height, &channels, 4), &stbi_image_free);
  if (!data)
    throw Error(ErrorKind::Parse, path,
                std::string("cannot read image: ") +
                    (stbi_failure_reason() ? stbi_failure_reason() : "unknown image error"));
  img.pixels.assign(data.get(), data.get() + size_t(img.width) * img.height * 4);
  return img;
}

void writePfm(const std::string& path, const ImageRGBA32F& image) {
  const std::string tmp = tempName(path);
  {
    errno = 0;
    std::ofstream out(tmp, std::ios::binary);
    if (!out)
      throw Error(
          ErrorKind::Output, path,
          std::string("cannot write PFM: ") + (errno ? std::strerror(errno) : "open failed"));
    out << "PF\n" << image.width << " " << image.height << "\n-1.0\n";  // -1: little-endian
    std::vector<float> row(size_t(image.width) * 3);
    for (int y = image.height - 1; y >= 0; --y) {
      for (int x = 0; x < image.width; ++x)
        for (int c = 0; c < 3; ++c)
          row[x * 3 + c] = image.pixels[(size_t(y) * image.width + x) * 4 + c];
      out.write(reinterpret_cast<const char*>(row.data()),
                std::streamsize(row.size() * sizeof(float)));
    }
    if (!out) {
      out.close();
      std::error_code ec;
      std::filesystem::remove(tmp, ec);
      throw Error(ErrorKind::Output, path, "write failed");
    }
  }
  commitFile(tmp, path);
}

ImageRGBA32F readPfm(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(ErrorKind::FileNotFound, path, "cannot open PFM");
  std::string magic;
  float scale = 0;
  ImageRGBA32F img;
  in >> magic >> img.width >> img.height >> scale;
  in.get();
  if (magic != "PF" || img.width <= 0 || img.height <= 0 || scale >= 0)
    throw Error(ErrorKind::Parse, path, "not a little-endian colour PFM");
  img.pixels.assign(size_t(img.width) * img.height * 4, 1.0f);
  std::vector<float> row(size_t(img.width) * 3);
  for (int y = img.height - 1; y >= 0; --y) {
    in.read(reinterpret_cast<char*>(row.data()), std::streamsize(row.size() * sizeof(float)));
    if (!in) throw Error(ErrorKind::Parse, path, "truncated PFM");
    for (int x = 0; x < img.width; ++x)
      for (int c = 0; c < 3; ++c) img.pixels[(size_t(y) * img.width + x) * 4 + c] = row[x * 3 + c];
  }
  return img;
}

float halfToFloat(uint16_t h) {
  const uint32_t sign = (h >> 15) & 1, exponent = (h >> 10) & 0x1f, mantissa = h & 0x3ff;
  float v;
  if (exponent == 0)
    v = std::ldexp(float(mantissa), -24);
  else if (exponent == 31)
    v = mantissa ? std::numeric_limits<float>::quiet_NaN() : std::numeric_limits<float>::infinity();
  else
    v = std::ldexp(float(mantissa | 0x400), int(exponent) - 25);
  return sign ? -v : v;
}

}  // namespace gi
