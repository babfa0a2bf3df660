// Renderer::setCameraOverride (gi-demo's walking camera): the scene's own camera given as an
// override renders the same image; a moved one renders another, keeps its view through a
// resize with the projection rebuilt for the new aspect, and nullopt returns to the scene's.
#include <gtest/gtest.h>

#include "gi/errors.h"
#include "gi/renderer.h"
#include "gi/scene_io.h"
#include "test_support.h"
#include "vulkan_fixture.h"

namespace gi {
namespace {

class CameraOverrideTest : public test::VulkanTest {
 protected:
  RenderSettings base() const {
    RenderSettings rs;
    rs.width = 96;
    rs.height = 72;
    return rs;
  }
  Scene scene_ = loadScene("default");
};

TEST_F(CameraOverrideTest, OverrideMovesTheViewAndFollowsTheAspect) {
  Renderer r(ctx(), scene_, base());
  r.renderFrame();
  const ImageRGBA8 original = r.readOutput();
  const CameraView sceneCamera = r.camera();

  r.setCameraOverride(sceneCamera);  // the same camera: the same image
  r.renderFrame();
  EXPECT_EQ(r.readOutput().pixels, original.pixels);

  CameraView moved = sceneCamera;
  moved.position += glm::vec3(0.3f, 0.1f, -0.5f);
  moved.view = lookAlong(moved.position, glm::vec3(0.2f, 0.0f, -1.0f));
  r.setCameraOverride(moved);
  EXPECT_EQ(r.camera().position, moved.position);
  EXPECT_EQ(r.camera().view, moved.view);
  r.renderFrame();
  const ImageRGBA8 away = r.readOutput();
  EXPECT_NE(away.pixels, original.pixels);

  RenderSettings wide = base();
  wide.width = 128;
  r.applySettings(wide);  // the override stays; its projection takes the new aspect
  EXPECT_EQ(r.camera().view, moved.view);
  const glm::mat4 expected =
      perspectiveReverseZ(moved.yfov, 128.0f / 72.0f, moved.znear, moved.zfar);
  for (int c = 0; c < 4; ++c)
    for (int k = 0; k < 4; ++k) EXPECT_FLOAT_EQ(r.camera().proj[c][k], expected[c][k]);

  r.applySettings(base());
  r.setCameraOverride(std::nullopt);  // back to the scene's camera
  r.renderFrame();
  EXPECT_EQ(r.readOutput().pixels, original.pixels);
}

TEST_F(CameraOverrideTest, RejectsADegenerateCamera) {
  Renderer r(ctx(), scene_, base());
  CameraView bad = r.camera();
  bad.znear = 0.0f;
  test::expectError([&] { r.setCameraOverride(bad); }, ErrorKind::InvalidData, {"camera override"});
  bad = r.camera();
  bad.yfov = 3.2f;
  test::expectError([&] { r.setCameraOverride(bad); }, ErrorKind::InvalidData, {"camera override"});
}

}  // namespace
}  // namespace gi
