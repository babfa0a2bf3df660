// The frame graph: passes declare what they read and write through typed, versioned handles;
// compile() culls every pass whose results do not reach a marked output, allocates transient
// images and buffers (aliasing memory between resources whose lifetimes do not overlap) and
// derives synchronization2 barriers from the declared usage; execute() records the kept
// passes, each timed with timestamp queries.
//
// Textures may have layers, mips, cube faces or depth (TextureDesc::type); passes may access a
// range of them (Subresource) and barriers are derived per (mip, layer). Persistent textures
// keep their contents across frames (history); readOptional() falls back to a neutral 1x1
// texture when no pass published an input.
#pragma once

#include <vulkan/vulkan.h>

#include <functional>
#include <memory>
#include <set>
#include <string>
#include <unordered_map>
#include <vector>

#include "gi/graph/handles.h"
#include "gi/vk/context.h"

namespace gi::vk {
class GpuTimer;
class DescriptorArena;
class DescriptorWriter;
class Pipeline;
}  // namespace gi::vk

namespace gi {

class FrameGraph;

// Given to a pass's execute callback: the command buffer and the real Vulkan objects behind
// the handles it declared.
class PassContext {
 public:
  VkCommandBuffer cmd() const { return cmd_; }
  vk::Context& context() const { return *ctx_; }
  vk::DescriptorArena& descriptors() const { return *descriptors_; }
  VkImage image(TextureHandle h) const;
  VkImageView view(TextureHandle h) const;  // whole texture, natural view type
  // That range: a 2-D view for one layer, 2-D array for several (3-D textures: a 3-D view of
  // those mips). Created on first use and cached with the image.
  VkImageView view(TextureHandle h, const Subresource& sub) const;
  VkExtent2D extent(TextureHandle h, uint32_t mip = 0) const;
  uint32_t layers(TextureHandle h) const;
  uint32_t mips(TextureHandle h) const;
  VkFormat format(TextureHandle h) const;
  VkBuffer buffer(BufferHandle h) const;
  VkDeviceSize bufferSize(BufferHandle h) const;
  VkExtent2D outputExtent() const;
  // Inside a pass that reads and writes the same range in the layout it declared (e.g. a
  // StorageWrite of all mips, generating mip i from mip i-1 with imageLoad/imageStore): makes
  // the pass's shader writes to `sub` so far visible to its later shader reads and writes.
  void barrier(TextureHandle h, const Subresource& sub) const;
  // Binds `pipeline` with `writer`'s descriptors and dispatches enough groupX x groupY
  // workgroups to cover `extent` (a compute pass's usual recording).
  void dispatch(const vk::Pipeline& pipeline, vk::DescriptorWriter& writer, VkExtent2D extent,
                uint32_t groupX, uint32_t groupY) const;
  // The same with `push` as the shader's push constants (vk::Pipeline::push checks its type).
  template <class T>
  void dispatch(const vk::Pipeline& pipeline, vk::DescriptorWriter& writer, VkExtent2D extent,
                uint32_t groupX, uint32_t groupY, const T& push) const {
    dispatchPushing(pipeline, writer, extent, groupX, groupY, &push, sizeof(T));
  }

 private:
  friend class FrameGraph;
  void dispatchGroups(VkExtent2D extent, uint32_t groupX, uint32_t groupY) const;
  void dispatchPushing(const vk::Pipeline& pipeline, vk::DescriptorWriter& writer,
                       VkExtent2D extent, uint32_t groupX, uint32_t groupY, const void* push,
                       size_t size) const;
  const FrameGraph* graph_ = nullptr;
  vk::Context* ctx_ = nullptr;
  vk::DescriptorArena* descriptors_ = nullptr;
  VkCommandBuffer cmd_ = VK_NULL_HANDLE;
};

using PassExecute = std::function<void(PassContext&)>;

// Given to a pass's setup callback: declares resources and their use.
class PassBuilder {
 public:
  TextureHandle create(const std::string& name, const TextureDesc& desc);
  BufferHandle create(const std::string& name, const BufferDesc& desc);
  // Declares a read of the current version of a resource (of `sub` only: the pass may access
  // other ranges of the same texture in other ways). Throws on a stale handle.
  TextureHandle read(TextureHandle h, TextureUsage usage = TextureUsage::Sampled,
                     const Subresource& sub = {});
  BufferHandle read(BufferHandle h, BufferUsage usage = BufferUsage::StorageRead);
  // Declares a write; the returned handle names the new version (use it from now on). A write
  // of part of a texture keeps the rest of the previous version: its producers stay alive.
  [[nodiscard]] TextureHandle write(TextureHandle h, TextureUsage usage,
                                    const Subresource& sub = {});
  [[nodiscard]] BufferHandle write(BufferHandle h, BufferUsage usage);
  // The blackboard texture `name` if a pass published it, else the graph's 1x1 neutral texture
  // declared with FrameGraph::declareFallback(name, ...) (throws gi::Error if neither). Shaders
  // must sample optional inputs with normalized coordinates (texture/textureLod), so 1x1 works.
  TextureHandle readOptional(const std::string& name, TextureUsage usage = TextureUsage::Sampled);
  bool isFallback(TextureHandle h) const;  // true when readOptional returned the neutral texture
  // Never culled (e.g. a pass that reads back to the host).
  void sideEffect();

 private:
  friend class FrameGraph;
  PassBuilder(FrameGraph& g, uint32_t pass) : graph_(g), pass_(pass) {}
  FrameGraph& graph_;
  uint32_t pass_;
};

// Named handles shared between passes and effects ("depth", "normal", "ao", ...): the one
// place where well-known resources are published and looked up. It records the names looked
// up and published since startTracking(), which the renderer checks against what an effect
// declared (EffectInfo::reads/writes).
class Blackboard {
 public:
  void put(const std::string& name, TextureHandle h) {
    textures_[name] = h;
    published_.insert(name);
  }
  void put(const std::string& name, BufferHandle h) {
    buffers_[name] = h;
    published_.insert(name);
  }
  void startTracking() {
    lookedUp_.clear();
    published_.clear();
  }
  const std::set<std::string>& lookedUp() const { return lookedUp_; }
  const std::set<std::string>& published() const { return published_; }
  TextureHandle texture(const std::string& name) const;  // invalid handle if absent
  BufferHandle buffer(const std::string& name) const;
  bool has(const std::string& name) const { return textures_.count(name) || buffers_.count(name); }
  std::vector<std::string> names() const;
  void clear();

 private:
  std::unordered_map<std::string, TextureHandle> textures_;
  std::unordered_map<std::string, BufferHandle> buffers_;
  mutable std::set<std::string> lookedUp_;
  std::set<std::string> published_;
};

struct GraphStats {
  size_t transientTextures = 0, transientBuffers = 0;
  VkDeviceSize transientBytesRequested = 0;  // sum of all transient resources
  VkDeviceSize transientBytesAllocated = 0;  // after aliasing
};

class FrameGraph {
 public:
  FrameGraph(vk::Context& ctx, VkExtent2D outputExtent);
  ~FrameGraph();
  FrameGraph(const FrameGraph&) = delete;
  FrameGraph& operator=(const FrameGraph&) = delete;

  // Adds a pass: `setup` declares resources now, `execute` records commands later. Passes must
  // be added in an order where every read refers to an earlier write (setup order).
  void addPass(const std::string& name, const std::function<void(PassBuilder&)>& setup,
               PassExecute execute);
  // The effect that adds the next passes ("" for the engine's own): a pass whose recording
  // throws is then an EffectError naming it. Cleared by reset().
  void setPassOwner(std::string effect) { passOwner_ = std::move(effect); }

  // External resources (created and owned elsewhere). `finalLayout` is the layout the image
  // is left in after execute() (UNDEFINED: wherever its last use left it).
  TextureHandle importTexture(const std::string& name, VkImage image, VkImageView view,
                              const TextureDesc& desc, VkImageLayout currentLayout,
                              VkImageLayout finalLayout = VK_IMAGE_LAYOUT_UNDEFINED);
  BufferHandle importBuffer(const std::string& name, VkBuffer buffer, VkDeviceSize size);

  // Marks a resource version as a result of the frame: culling walks back from these, and
  // its memory is not reused by later passes (it can be read after execute()).
  void markOutput(TextureHandle h);
  void markOutput(BufferHandle h);
  // After compile(): false when a later pass's transient shares this texture's memory
  // (aliasing), so after execute() it no longer holds its own contents. Outputs, imported and
  // persistent textures are always intact.
  bool intactAtEnd(TextureHandle h) const;
  // After compile(): whether the texture exists this frame (false: its passes were culled).
  bool produced(TextureHandle h) const;
  VkFormat textureFormat(TextureHandle h) const;  // as declared

  Blackboard& blackboard() { return blackboard_; }
  VkExtent2D outputExtent() const { return outputExtent_; }
  void setOutputExtent(VkExtent2D e);  // only between reset() and compile()

  // A neutral 1x1 texture readOptional(name) returns when no pass published `name` (e.g. "ao"
  // = 1). Kept across reset(); declaring it again with the same format and value is a no-op.
  void declareFallback(const std::string& name, VkFormat format, VkClearColorValue value);
  // Persistent texture owned by the graph: survives reset()/compile() and frames, so at the
  // start of a frame it holds what the last executed frame left (history for temporal effects).
  // Must be declared again (same name) after every reset(); recreated and cleared to zero when
  // its resolved size/format/type changes (e.g. output resize); persistent textures not declared
  // by the time of compile() are freed. Its last version is an implicit output: passes writing
  // it are not culled. The handle's version 0 is last frame's contents.
  TextureHandle persistentTexture(const std::string& name, const TextureDesc& desc);
  // False until one frame has written it since (re)creation (also answers during setup).
  bool historyValid(TextureHandle h) const;
  // Frees persistent and fallback textures (and forgets the fallbacks); not while compiled.
  void releasePersistent();

  // Debug: false gives every transient its own memory, so that after execute() each one still
  // holds its last version (a sweep reads them all back: allocatedTextures()). Takes effect at
  // the next compile(). Default true (lifetimes that do not overlap share memory).
  void setAliasing(bool on) { aliasing_ = on; }
  bool aliasing() const { return aliasing_; }

  void compile();
  // Records every kept pass into `cmd` (after compile()); timer may be null. `afterPass`,
  // when given, runs after each pass with the command buffer recorded so far and returns the
  // one to record the next pass into (a profiler submits and waits there, so that each pass
  // runs alone: drivers that overlap or defer work then still time each pass correctly).
  using PassBoundary = std::function<VkCommandBuffer(VkCommandBuffer)>;
  void execute(VkCommandBuffer cmd, vk::DescriptorArena& descriptors, vk::GpuTimer* timer,
               const PassBoundary& afterPass = {});
  // Drops all passes and resources declared so far and frees transient memory (persistent and
  // fallback textures stay).
  void reset();

  std::vector<std::string> passNames() const;  // every pass added so far, in order
  std::vector<std::string> executedPasses() const;
  std::vector<std::string> culledPasses() const;
  std::string toDot() const;     // Graphviz: kept passes solid, culled passes dashed
  std::string describe() const;  // human-readable listing (gi-render --print-graph)
  const GraphStats& stats() const { return stats_; }
  bool compiled() const { return compiled_; }
  // The Vulkan image behind a handle and the layout the last execute() left it in (for
  // read-back and presentation). Throws if the resource was culled (never allocated).
  struct TextureState {
    VkImage image;
    VkImageView view;
    VkFormat format;
    VkExtent2D extent;     // of mip 0
    VkImageLayout layout;  // of mip 0, layer 0
  };
  TextureState textureState(TextureHandle h) const;
  // Every texture a kept pass of the compiled graph used (transient, persistent, fallback or
  // imported), in declaration order, with its name and state. With aliasing on, a transient's
  // memory may hold a later alias's texels after execute(): read them with setAliasing(false).
  std::vector<std::pair<std::string, TextureState>> allocatedTextures() const;

 private:
  friend class PassBuilder;
  friend class PassContext;
  struct Resource;
  struct Pass;
  struct Access;
  struct Transient;
  struct Slot;
  struct Owned;  // a persistent or fallback image

  std::string passOwner_;

  uint32_t addResource(const std::string& name, bool texture);
  void checkCurrent(uint32_t id, uint32_t version, const char* what, const std::string& pass) const;
  VkExtent2D resolveExtent(uint32_t id) const;
  void resolveTextures();
  void allocateTransients();
  void preparePersistent();
  void clearOwned(VkCommandBuffer cmd);
  const Resource& resource(uint32_t id) const;

  vk::Context& ctx_;
  VkExtent2D outputExtent_;
  std::vector<std::unique_ptr<Resource>> resources_;
  std::vector<std::unique_ptr<Pass>> passes_;
  std::vector<std::pair<uint32_t, uint32_t>> outputs_;  // (resource, version)
  std::vector<std::unique_ptr<Transient>> pool_;        // transient images and buffers
  std::vector<Slot> slots_;                             // their (aliased) memory
  std::unordered_map<std::string, std::unique_ptr<Owned>> persistent_, fallbacks_;
  std::unordered_map<std::string, uint32_t> fallbackIds_;  // fallback resources of this graph
  Blackboard blackboard_;
  GraphStats stats_;
  bool compiled_ = false;
  bool aliasing_ = true;
};

}  // namespace gi
