// Float render target -> 8-bit preview, shared by gi-render (--view X --out F.png) and gi-demo.
#pragma once

#include <string>

#include "gi/image_io.h"

namespace gi::app {

// Values clamped to [0,1]; normals and motion (signed) shifted by 0.5 to be visible; depth and
// AO (one channel) shown as grey; alpha opaque. NaN and Inf show as black, never as a cast of a
// non-finite float to a byte (undefined behaviour).
ImageRGBA8 previewOf(const ImageRGBA32F& image, const std::string& view);

// What a float view (--out F.pfm) holds: the target's channels, except for the one-channel
// resources (depth, ao), whose R is copied to G and B and alpha set to 1. Their other channels
// are the producer's own: the AO family's unblurred texel (blur_radius = 0) carries 1 / view
// distance and the tangent plane's signed slopes there, which no view should show as data.
ImageRGBA32F definedChannels(ImageRGBA32F image, const std::string& view);

}  // namespace gi::app
