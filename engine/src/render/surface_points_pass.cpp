#include "render/surface_points_pass.h"

#include <algorithm>
#include <cstring>
#include <map>
#include <memory>

#include "gi/effect.h"
#include "gi/errors.h"

namespace gi {
namespace {

constexpr VkDeviceSize kPointBytes = 2 * sizeof(glm::vec4);

// Dispatches n invocations of a 256-wide workgroup as a 2-D grid: one row holds at most 65535
// groups (the guaranteed maxComputeWorkGroupCount); the shaders flatten the grid again.
void dispatch256(VkCommandBuffer cmd, uint64_t n) {
  const uint64_t groups = (n + 255) / 256;
  if (groups == 0) return;
  const uint64_t x = std::min<uint64_t>(groups, 65535);
  vkCmdDispatch(cmd, uint32_t(x), uint32_t((groups + x - 1) / x), 1);
}

}  // namespace

SurfacePointsPass::SurfacePointsPass(vk::Context& ctx, const Scene& scene, uint32_t count,
                                     uint64_t seed, const std::vector<InstanceRef>& instances)
    : set_(sampleSurfacePoints(scene, count, seed)) {
  std::map<std::pair<int, int>, const InstanceRef*> byNodeMesh;
  for (const InstanceRef& r : instances) byNodeMesh[{r.node, r.mesh}] = &r;
  std::vector<glm::uvec4> packed;
  packed.reserve(set_.points.size());
  for (const SurfacePoint& p : set_.points) {
    auto it = byNodeMesh.find({int(p.node), int(p.mesh)});
    if (it == byNodeMesh.end())
      throw Error(ErrorKind::InvalidData, scene.sourcePath,
                  "surface point on a mesh instance the renderer does not draw");
    glm::uvec4 s(it->second->instance, it->second->firstIndex + 3 * p.triangle, 0u, 0u);
    std::memcpy(&s.z, &p.barycentric.x, 4);
    std::memcpy(&s.w, &p.barycentric.y, 4);
    packed.push_back(s);
  }
  // Keep the buffers non-empty so the descriptors stay valid for a scene without area.
  if (packed.empty()) packed.emplace_back(0u);
  samples_ = vk::createDeviceBuffer(ctx, packed.data(), packed.size() * sizeof(glm::uvec4),
                                    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  // Zeros until the pass first runs: a read-back never sees uninitialised memory.
  const std::vector<glm::vec4> zeros(packed.size() * 2, glm::vec4(0.0f));
  points_ =
      vk::createDeviceBuffer(ctx, zeros.data(), zeros.size() * sizeof(glm::vec4),
                             VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  vk::ComputeDesc update{"surface points: surface_points.comp",
                         vk::loadSpirv("surface_points.comp")};
  update.blocks.pushConstants = GI_CPP_BLOCK(UpdatePush, count, areaPerPoint);
  update_ = vk::Pipeline::compute(ctx, update);
  vk::ComputeDesc view{"surface points: points_view.comp", vk::loadSpirv("points_view.comp")};
  view.blocks.pushConstants = GI_CPP_BLOCK(ViewPush, count, clear);
  view_ = vk::Pipeline::compute(ctx, view);
}

void SurfacePointsPass::addPasses(FrameGraph& graph, BufferHandle vertices, const Buffers& in) {
  Blackboard& bb = graph.blackboard();
  BufferHandle points =
      graph.importBuffer(resources::kSurfacePoints, points_.handle(), points_.size());
  auto out = std::make_shared<BufferHandle>();
  graph.addPass(
      "surface_points",
      [&](PassBuilder& b) {
        if (vertices.valid()) b.read(vertices, BufferUsage::StorageRead);
        *out = b.write(points, BufferUsage::StorageWrite);
      },
      [this, in](PassContext& pc) {
        // The buffer is imported (persistent): an unchanged pose leaves valid points in it.
        const uint64_t version = in.poseVersion ? *in.poseVersion : 0;
        if (evaluated_ && version != 0 && version == evaluatedVersion_) return;
        vk::DescriptorWriter w(update_);
        w.buffer("Samples", samples_.handle())
            .buffer("Instances", in.instances)
            .buffer("Indices", in.indices)
            .buffer("Vertices", in.vertices)
            .buffer("Points", points_.handle());
        pc.descriptors().bind(pc.cmd(), update_, w);
        update_.push(pc.cmd(),
                     UpdatePush{count(), count() ? float(set_.totalArea / count()) : 0.0f});
        dispatch256(pc.cmd(), count());
        evaluated_ = true;
        evaluatedVersion_ = version;
        ++evaluations_;
      });
  bb.put(resources::kSurfacePoints, *out);

  struct ViewIo {
    BufferHandle points;
    TextureHandle depth, image;
  };
  auto view = std::make_shared<ViewIo>();
  graph.addPass(
      "points_view",
      [&](PassBuilder& b) {
        view->points = b.read(*out, BufferUsage::StorageRead);
        view->depth = b.read(bb.texture(resources::kDepth));
        TextureDesc desc{VK_FORMAT_R16G16B16A16_SFLOAT};
        view->image = b.write(b.create(resources::kPointsView, desc), TextureUsage::StorageWrite);
      },
      [this, in, view](PassContext& pc) {
        vk::DescriptorWriter w(view_);
        w.buffer("Frame", in.frameUniforms)
            .buffer("Points", pc.buffer(view->points))
            .texture("depthTex", pc.view(view->depth), in.nearest)
            .image("outImage", pc.view(view->image));
        pc.descriptors().bind(pc.cmd(), view_, w);
        const VkExtent2D e = pc.extent(view->image);
        view_.push(pc.cmd(), ViewPush{0u, 1u});
        dispatch256(pc.cmd(), uint64_t(e.width) * e.height);
        // The splats overwrite cleared texels: order the two dispatches.
        VkMemoryBarrier2 barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER_2};
        barrier.srcStageMask = barrier.dstStageMask = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
        barrier.srcAccessMask = barrier.dstAccessMask = VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT;
        VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
        dep.memoryBarrierCount = 1;
        dep.pMemoryBarriers = &barrier;
        vkCmdPipelineBarrier2(pc.cmd(), &dep);
        view_.push(pc.cmd(), ViewPush{count(), 0u});
        dispatch256(pc.cmd(), count());
      });
  bb.put(resources::kPointsView, view->image);
}

std::vector<SurfacePointSample> SurfacePointsPass::read(vk::Context& ctx) const {
  if (!evaluated_) return {};
  std::vector<SurfacePointSample> out(count());
  if (out.empty()) return out;
  vk::Buffer staging(ctx, points_.size(), VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
  ctx.submitAndWait([&](VkCommandBuffer c) {
    VkBufferCopy copy{0, 0, points_.size()};
    vkCmdCopyBuffer(c, points_.handle(), staging.handle(), 1, &copy);
  });
  static_assert(sizeof(SurfacePointSample) == kPointBytes);
  std::memcpy(out.data(), staging.mapped(), out.size() * sizeof(SurfacePointSample));
  return out;
}

}  // namespace gi
