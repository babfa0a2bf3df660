// Float render target -> 8-bit preview, shared by gi-render (--view X --out F.png) and gi-demo.
#pragma once

#include <string>

#include "gi/image_io.h"

namespace gi::app {

// Values clamped to [0,1]; normals and motion (signed) shifted by 0.5 to be visible; depth and
// AO (one channel) shown as grey; alpha opaque. NaN and Inf show as black, never as a cast of a
// non-finite float to a byte (undefined behaviour).
ImageRGBA8 previewOf(const ImageRGBA32F& image, const std::string& view);

}  // namespace gi::app
