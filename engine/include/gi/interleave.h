// The 4x4 interleave pattern of the screen-space effects: pixel (x, y) is phase
// e = (y & 3) * 4 + (x & 3) and takes the e-th of 16 kernel rotations (and step jitters); a
// blur whose footprint covers the 4x4 block averages the pattern away.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>

namespace gi {

// 4x4 Bayer order: entry e holds the phase's rank j in 0..15.
inline constexpr std::array<int, 16> kBayer4 = {0, 8,  2, 10, 12, 4, 14, 6,
                                                3, 11, 1, 9,  15, 7, 13, 5};

// The rotation (a fraction of the angle between two directions) and step jitter of phase e: both
// strata midpoints, the jitter in another order (rank x 5 mod 16) to decorrelate them. Without
// interleaving every pixel takes the midpoints (0.5, 0.5).
inline std::array<float, 2> interleaveNoise(int e, bool interleave) {
  if (!interleave) return {0.5f, 0.5f};
  const int j = kBayer4[size_t(e)];
  return {(float(j) + 0.5f) / 16.0f, (float((j * 5) % 16) + 0.5f) / 16.0f};
}

// A std140 table of the 16 phases: cos and sin of the rotation noise.x x `period` / `count`
// (count directions or slices repeating every `period` radians), the step jitter, 0.
inline void interleaveRotations(float (&table)[16][4], double period, int count, bool interleave) {
  for (int e = 0; e < 16; ++e) {
    const auto n = interleaveNoise(e, interleave);
    const double rotation = n[0] * period / (count < 1 ? 1 : count);
    table[e][0] = float(std::cos(rotation));
    table[e][1] = float(std::sin(rotation));
    table[e][2] = n[1];
  }
}

}  // namespace gi
