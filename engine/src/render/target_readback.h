// Copies frame-graph images back to the host (Renderer::readTarget / readOutput).
#pragma once

#include <string>
#include <vector>

#include "gi/graph/frame_graph.h"
#include "gi/image_io.h"

namespace gi {

// Raw texels of mip 0, layer 0, tightly packed; leaves the image in its layout.
std::vector<uint8_t> readTexels(vk::Context& ctx, const FrameGraph::TextureState& t);
// True for the formats texelsToFloat reads.
bool canDecode(VkFormat format);
// The texels as float RGBA (sRGB decoded, depth in r); throws for unsupported formats.
ImageRGBA32F texelsToFloat(const std::vector<uint8_t>& raw, const FrameGraph::TextureState& t,
                           const std::string& name);

}  // namespace gi
