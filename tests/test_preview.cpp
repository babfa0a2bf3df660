// The apps' 8-bit preview of a float target (apps/common/preview.h).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "gi/effect.h"
#include "preview.h"

namespace {

gi::ImageRGBA32F onePixel(float r, float g, float b, float a) {
  return gi::ImageRGBA32F{1, 1, {r, g, b, a}};
}

TEST(Preview, NonFiniteValuesShowAsBlackAndAlphaIsOpaque) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  const gi::ImageRGBA8 out = gi::app::previewOf(onePixel(nan, inf, -inf, nan), "lit");
  EXPECT_EQ(out.pixels[0], 0);
  EXPECT_EQ(out.pixels[1], 0);
  EXPECT_EQ(out.pixels[2], 0);
  EXPECT_EQ(out.pixels[3], 255);
}

TEST(Preview, ClampsRoundsAndShiftsSignedData) {
  const gi::ImageRGBA8 lit = gi::app::previewOf(onePixel(0.5f, 2.0f, -1.0f, 0.0f), "lit");
  EXPECT_EQ(lit.pixels[0], 128);  // 127.5 rounds up
  EXPECT_EQ(lit.pixels[1], 255);
  EXPECT_EQ(lit.pixels[2], 0);
  const gi::ImageRGBA8 normal =
      gi::app::previewOf(onePixel(-1.0f, 0.0f, 1.0f, 0.0f), gi::resources::kNormal);
  EXPECT_EQ(normal.pixels[0], 0);
  EXPECT_EQ(normal.pixels[1], 128);
  EXPECT_EQ(normal.pixels[2], 255);
}

TEST(Preview, OneChannelTargetsAreGrey) {
  const gi::ImageRGBA8 ao =
      gi::app::previewOf(onePixel(0.25f, 9.0f, 9.0f, 9.0f), gi::resources::kAO);
  EXPECT_EQ(ao.pixels[0], 64);
  EXPECT_EQ(ao.pixels[1], 64);
  EXPECT_EQ(ao.pixels[2], 64);
  EXPECT_EQ(ao.pixels[3], 255);
}

// A float view of a one-channel resource holds its R alone (the AO family's unblurred texel
// has 1/z and signed slopes in G..A); other views keep every channel.
TEST(Preview, FloatViewsOfOneChannelTargetsHoldOnlyTheirChannel) {
  const gi::ImageRGBA32F ao =
      gi::app::definedChannels(onePixel(0.25f, 3.0f, -0.5f, 0.1f), gi::resources::kAO);
  EXPECT_EQ(ao.pixels, (std::vector<float>{0.25f, 0.25f, 0.25f, 1.0f}));
  const gi::ImageRGBA32F lit = gi::app::definedChannels(onePixel(0.25f, 3.0f, -0.5f, 0.1f), "lit");
  EXPECT_EQ(lit.pixels, (std::vector<float>{0.25f, 3.0f, -0.5f, 0.1f}));
}

}  // namespace
