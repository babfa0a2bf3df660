// Typed settings: every type parses from JSON and from --set text, round-trips through
// toJson(), and refuses bad values with a message naming the key (and the option or the
// component); the builders; the checks on declarations, also applied by the effect registry.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "gi/effect_registry.h"
#include "gi/errors.h"
#include "gi/settings.h"
#include "test_support.h"

namespace gi {
namespace {

using nlohmann::json;

std::vector<SettingDesc> allTypes() {
  SettingDesc radius{"radius", SettingType::Float, 0.5, 1e-4, 1e4, "world radius", false};
  radius.logScale = true;
  radius.step = 0.01;
  return {
      {"enabled", SettingType::Bool, 1, 0, 1, "on or off", false},
      {"samples", SettingType::Int, 8, 1, 64, "sample count", true},
      radius,
      SettingDesc::enumeration("filter", {"box", "tent", "gauss"}, 1, "filter kernel", true),
      SettingDesc::vec3("offset", {0, 1, -2}, -10, 10, "offset in metres"),
      SettingDesc::color("tint", {1, 0.5, 0.25}, "tint (linear RGB)", 4.0),
  };
}

SettingValues fresh() {
  return SettingValues("fx", allTypes());
}

using test::expectError;

using Vec = std::array<double, 3>;

TEST(Settings, DefaultsOfEveryType) {
  const SettingValues s = fresh();
  EXPECT_TRUE(s.flag("enabled"));
  EXPECT_EQ(s.integer("samples"), 8);
  EXPECT_DOUBLE_EQ(s.number("radius"), 0.5);
  EXPECT_EQ(s.option("filter"), "tent");
  EXPECT_EQ(s.integer("filter"), 1);  // an enum's integer is its index
  EXPECT_EQ(s.vector("offset"), (Vec{0, 1, -2}));
  EXPECT_EQ(s.vector("tint"), (Vec{1, 0.5, 0.25}));
}

TEST(Settings, EveryTypeParsesFromJson) {
  SettingValues s = fresh();
  s.set("enabled", false, "f.json");
  s.set("samples", 32, "f.json");
  s.set("samples", 16.0, "f.json");  // an integral number is an integer
  s.set("radius", 2.25, "f.json");
  s.set("filter", "gauss", "f.json");
  s.set("offset", json::array({1.5, -3, 10}), "f.json");
  s.set("tint", json::array({0, 4, 0.125}), "f.json");
  EXPECT_FALSE(s.flag("enabled"));
  EXPECT_EQ(s.integer("samples"), 16);
  EXPECT_DOUBLE_EQ(s.number("radius"), 2.25);
  EXPECT_EQ(s.option("filter"), "gauss");
  EXPECT_EQ(s.integer("filter"), 2);
  EXPECT_EQ(s.vector("offset"), (Vec{1.5, -3, 10}));
  EXPECT_EQ(s.vector("tint"), (Vec{0, 4, 0.125}));
}

TEST(Settings, EveryTypeParsesFromSetText) {
  SettingValues s = fresh();
  s.setFromString("enabled", "false", "--set");
  s.setFromString("samples", "64", "--set");
  s.setFromString("radius", "1e-3", "--set");
  s.setFromString("filter", "box", "--set");
  s.setFromString("offset", "1,2,3", "--set");
  s.setFromString("tint", "[0.5, 0.25, 2]", "--set");
  EXPECT_FALSE(s.flag("enabled"));
  EXPECT_EQ(s.integer("samples"), 64);
  EXPECT_DOUBLE_EQ(s.number("radius"), 1e-3);
  EXPECT_EQ(s.option("filter"), "box");
  EXPECT_EQ(s.vector("offset"), (Vec{1, 2, 3}));
  EXPECT_EQ(s.vector("tint"), (Vec{0.5, 0.25, 2}));
  s.setFromString("filter", "\"tent\"", "--set");  // a JSON string works too
  EXPECT_EQ(s.option("filter"), "tent");
  s.setFromString("offset", " -1 , 0.5,7 ", "--set");
  EXPECT_EQ(s.vector("offset"), (Vec{-1, 0.5, 7}));
}

TEST(Settings, ToJsonWritesNamesAndArraysAndRoundTrips) {
  SettingValues s = fresh();
  s.set("filter", "gauss", "t");
  s.set("offset", json::array({-1, 2.5, 3}), "t");
  s.set("samples", 12, "t");
  const json j = s.toJson();
  EXPECT_EQ(j["enabled"], json(true));
  EXPECT_TRUE(j["samples"].is_number_integer());
  EXPECT_EQ(j["samples"], 12);
  EXPECT_EQ(j["radius"], 0.5);
  EXPECT_EQ(j["filter"], "gauss");
  EXPECT_EQ(j["offset"], json::array({-1.0, 2.5, 3.0}));
  EXPECT_EQ(j["tint"], json::array({1.0, 0.5, 0.25}));
  SettingValues back = fresh();
  for (auto it = j.begin(); it != j.end(); ++it) back.set(it.key(), it.value(), "round trip");
  EXPECT_EQ(back.toJson(), j);
  EXPECT_FALSE(back.graphDiffers(s));
  EXPECT_FALSE(s.graphDiffers(back));
}

TEST(Settings, BadValuesNameTheKeyOptionOrComponent) {
  SettingValues s = fresh();
  expectError([&] { s.set("filter", "sinc", "p.json"); }, ErrorKind::Schema,
              {"p.json", "fx.filter", "unknown option 'sinc'", "box, tent, gauss"});
  expectError([&] { s.setFromString("filter", "sinc", "--set"); }, ErrorKind::Schema,
              {"--set", "fx.filter", "'sinc'", "box, tent, gauss"});
  expectError([&] { s.set("filter", 1, "p.json"); }, ErrorKind::Schema,
              {"fx.filter", "one of: box, tent, gauss"});
  expectError(
      [&] {
        s.set("offset", json::array({1, 2}), "p.json");
      },
      ErrorKind::Schema, {"p.json", "fx.offset", "3 components", "[1,2]"});
  expectError([&] { s.set("offset", 1.0, "p.json"); }, ErrorKind::Schema,
              {"fx.offset", "3 components"});
  expectError([&] { s.setFromString("offset", "1,2,3,4", "--set"); }, ErrorKind::Schema,
              {"--set", "fx.offset", "3 components"});
  expectError([&] { s.setFromString("offset", "1,2,", "--set"); }, ErrorKind::Schema,
              {"fx.offset: component 2 (z)", "expected a number"});
  expectError([&] { s.setFromString("offset", "1,abc,3", "--set"); }, ErrorKind::Schema,
              {"fx.offset: component 1 (y)", "\"abc\""});
  expectError(
      [&] {
        s.set("offset", json::array({1, 11, 0}), "p.json");
      },
      ErrorKind::InvalidData, {"p.json", "fx.offset: component 1 (y)", "[-10, 10]", "11"});
  expectError([&] { s.setFromString("offset", "nan,0,0", "--set"); }, ErrorKind::InvalidData,
              {"fx.offset: component 0 (x)", "finite", "nan"});
  expectError([&] { s.setFromString("tint", "1,1,inf", "--set"); }, ErrorKind::InvalidData,
              {"fx.tint: component 2 (b)", "finite"});
  expectError(
      [&] {
        s.set("tint", json::array({-0.5, 0, 0}), "p.json");
      },
      ErrorKind::InvalidData, {"fx.tint: component 0 (r)", "[0, 4]", "-0.5"});
  expectError([&] { s.set("radius", std::numeric_limits<double>::quiet_NaN(), "p.json"); },
              ErrorKind::InvalidData, {"fx.radius"});
  expectError([&] { s.set("samples", 65, "p.json"); }, ErrorKind::InvalidData,
              {"fx.samples", "[1, 64]", "65"});
  expectError([&] { s.set("colour", 1, "p.json"); }, ErrorKind::Schema,
              {"p.json", "fx.colour", "unknown setting", "filter", "tint"});
  // A failed set leaves the previous value.
  EXPECT_EQ(s.vector("offset"), (Vec{0, 1, -2}));
  EXPECT_EQ(s.option("filter"), "tent");
}

TEST(Settings, AccessorsRefuseTheWrongType) {
  const SettingValues s = fresh();
  expectError([&] { s.number("offset"); }, ErrorKind::Schema, {"fx.offset", "vec3"});
  expectError([&] { s.integer("tint"); }, ErrorKind::Schema, {"fx.tint", "color"});
  expectError([&] { s.option("samples"); }, ErrorKind::Schema, {"fx.samples", "not an enum"});
  expectError([&] { s.vector("radius"); }, ErrorKind::Schema, {"fx.radius", "float"});
}

// Typed handles: found once by name, read without a string look-up, following every change
// made through set(); a copy of the values reads through the same handle.
TEST(Settings, TypedHandlesReadTheCurrentValue) {
  SettingValues s = fresh();
  const Setting<double> radius = s.handle<double>("radius");
  const Setting<int> samples = s.handle<int>("samples"), filter = s.handle<int>("filter");
  const Setting<bool> enabled = s.handle<bool>("enabled");
  EXPECT_EQ(s[radius], 0.5);
  EXPECT_EQ(s[samples], 8);
  EXPECT_EQ(s[filter], 1);
  EXPECT_TRUE(s[enabled]);
  s.set("radius", 2.25, "t");
  s.setFromString("samples", "33", "t");
  s.set("filter", "gauss", "t");
  s.set("enabled", false, "t");
  const SettingValues copy = s;
  for (const SettingValues* v : {static_cast<const SettingValues*>(&s), &copy}) {
    EXPECT_EQ((*v)[radius], 2.25);
    EXPECT_EQ((*v)[samples], 33);
    EXPECT_EQ((*v)[filter], 2);
    EXPECT_FALSE((*v)[enabled]);
  }
  expectError([&] { s.handle<double>("radius2"); }, ErrorKind::Schema, {"fx.radius2", "unknown"});
  expectError([&] { s.handle<bool>("samples"); }, ErrorKind::Schema, {"fx.samples", "a bool"});
  expectError([&] { s.handle<int>("radius"); }, ErrorKind::Schema, {"fx.radius", "an int"});
  expectError([&] { s.handle<double>("offset"); }, ErrorKind::Schema, {"fx.offset", "a number"});
  // A handle of a longer declaration used on a shorter one is refused, not read out of range.
  const SettingValues one("fx", {allTypes()[0]});
  expectError([&] { one[s.handle<double>("radius")]; }, ErrorKind::Schema, {"another declaration"});
}

TEST(Settings, AdoptKeepsValuesWhoseNameAndTypeStillFit) {
  // A rebuilt plugin's declaration against the values the user had set (plugin hot reload).
  using T = SettingType;
  SettingDesc mode{"mode", T::Enum, 0, 0, 0, "", false, {"fast", "exact", "debug"}};
  SettingValues before("fx", {{"radius", T::Float, 0.5, 0.0, 10.0, ""},
                              {"taps", T::Int, 8, 1, 64, ""},
                              {"wide", T::Float, 0.5, 0.0, 10.0, ""},
                              {"gone", T::Bool, 0, 0, 1, ""},
                              mode,
                              {"tint", T::Color, 0, 0, 1, "", false, {}, {1, 1, 1}}});
  before.set("radius", 2.5, "test");
  before.set("taps", 32, "test");
  before.set("wide", 8.0, "test");
  before.set("mode", "debug", "test");
  before.set("tint", nlohmann::json::array({0.1, 0.2, 0.3}), "test");
  mode.options = {"fast", "exact"};  // "debug" removed
  SettingValues after("fx", {{"radius", T::Float, 1.0, 0.0, 10.0, ""},
                             {"taps", T::Bool, 0, 0, 1, ""},         // type changed
                             {"wide", T::Float, 0.5, 0.0, 4.0, ""},  // 8 is out of range now
                             mode,
                             {"tint", T::Color, 0, 0, 1, "", false, {}, {1, 1, 1}},
                             {"fresh", T::Int, 3, 0, 9, ""}});
  EXPECT_EQ(after.adopt(before), (std::vector<std::string>{"radius", "tint"}));
  EXPECT_DOUBLE_EQ(after.number("radius"), 2.5);
  EXPECT_FALSE(after.flag("taps"));
  EXPECT_DOUBLE_EQ(after.number("wide"), 0.5);
  EXPECT_EQ(after.option("mode"), "fast");
  EXPECT_EQ(after.vector("tint"), (std::array<double, 3>{0.1, 0.2, 0.3}));
  EXPECT_EQ(after.integer("fresh"), 3);
}

TEST(Settings, GraphDiffersComparesVectorsAndEnums) {
  SettingValues a = fresh(), b = fresh();
  b.set("offset", json::array({0, 1, -1}), "t");  // offset is uniform-only
  EXPECT_FALSE(a.graphDiffers(b));
  b.set("filter", "box", "t");  // filter changes the graph
  EXPECT_TRUE(a.graphDiffers(b));
  SettingDesc pos = SettingDesc::vec3("pos", {0, 0, 0}, -1, 1, "p", true);
  SettingValues c("fx", {pos}), d("fx", {pos});
  d.set("pos", json::array({0, 0, 0.5}), "t");
  EXPECT_TRUE(c.graphDiffers(d));
}

TEST(Settings, Builders) {
  const SettingDesc e = SettingDesc::enumeration("mode", {"a", "b"}, 1, "help", true);
  EXPECT_EQ(e.type, SettingType::Enum);
  EXPECT_EQ(e.options, (std::vector<std::string>{"a", "b"}));
  EXPECT_EQ(e.defaultValue, 1.0);
  EXPECT_EQ(e.minValue, 0.0);
  EXPECT_EQ(e.maxValue, 1.0);
  EXPECT_TRUE(e.changesGraph);
  EXPECT_EQ(e.help, "help");
  const SettingDesc v = SettingDesc::vec3("dir", {0, -1, 0}, -1, 1, "h");
  EXPECT_EQ(v.type, SettingType::Vec3);
  EXPECT_EQ(v.defaultVector, (Vec{0, -1, 0}));
  EXPECT_EQ(v.minValue, -1.0);
  EXPECT_EQ(v.maxValue, 1.0);
  EXPECT_FALSE(v.changesGraph);
  const SettingDesc c = SettingDesc::color("albedo", {0.5, 0.5, 0.5}, "h");
  EXPECT_EQ(c.type, SettingType::Color);
  EXPECT_EQ(c.minValue, 0.0);
  EXPECT_EQ(c.maxValue, 1.0);
  EXPECT_EQ(SettingDesc::color("e", {2, 2, 2}, "h", 10.0, true).maxValue, 10.0);
  // The existing aggregate form still compiles and keeps the hints at their defaults.
  const SettingDesc old{"radius", SettingType::Float, 0.5, 1e-4, 1e4, "help", false};
  EXPECT_EQ(old.step, 0.0);
  EXPECT_FALSE(old.logScale);
  EXPECT_TRUE(old.options.empty());
  EXPECT_NO_THROW(validateSettingDescs("fx", allTypes()));
}

TEST(Settings, DeclarationsAreChecked) {
  auto bad = [](SettingDesc d, const std::string& fragment) {
    expectError([&] { validateSettingDescs("effect 'fx'", {d}); }, ErrorKind::InvalidData,
                {"effect 'fx'", "setting '" + d.name + "'", fragment});
  };
  bad(SettingDesc::enumeration("mode", {"a", "b"}, 2, "h"), "default index 2");
  bad(SettingDesc::enumeration("mode", {"a", "b"}, -1, "h"), "default index -1");
  bad(SettingDesc::enumeration("mode", {}, 0, "h"), "at least one option");
  bad(SettingDesc::enumeration("mode", {"a", "b", "a"}, 0, "h"), "option 'a' listed twice");
  bad(SettingDesc::enumeration("mode", {"a", ""}, 0, "h"), "empty option");
  SettingDesc logZero{"r", SettingType::Float, 0.5, 0.0, 1.0, "h"};
  logZero.logScale = true;
  bad(logZero, "logScale needs min > 0");
  SettingDesc logBool{"b", SettingType::Bool, 0, 0, 1, "h"};
  logBool.logScale = true;
  bad(logBool, "logScale");
  bad(SettingDesc::vec3("v", {0, 2, 0}, -1, 1, "h"), "component y");
  bad(SettingDesc::color("c", {0, 0, 1.5}, "h"), "component b");
  bad(SettingDesc::vec3("v", {0, 0, 0}, 1, -1, "h"), "range [1, -1]");
  bad({"f", SettingType::Float, 2, 0, 1, "h"}, "default is outside its range");
  bad({"i", SettingType::Int, 2.5, 0, 4, "h"}, "integer");
  bad({"f", SettingType::Float, 0, 0, std::numeric_limits<double>::infinity(), "h"}, "not finite");
  SettingDesc negativeStep{"f", SettingType::Float, 0.5, 0, 1, "h"};
  negativeStep.step = -0.1;
  bad(negativeStep, "step");
  SettingDesc optionsOnFloat{"f", SettingType::Float, 0.5, 0, 1, "h"};
  optionsOnFloat.options = {"a"};
  bad(optionsOnFloat, "only for enum");
  expectError(
      [] {
        validateSettingDescs(
            "fx", {{"a", SettingType::Float, 0, 0, 1, "h"}, {"a", SettingType::Int, 0, 0, 1, "h"}});
      },
      ErrorKind::InvalidData, {"fx: setting 'a' declared twice"});
}

// An effect declaring what the test asks for.
class Declares : public Effect {
 public:
  Declares(std::string name, std::vector<SettingDesc> settings)
      : name_(std::move(name)), settings_(std::move(settings)) {}
  EffectInfo info() const override {
    return {name_, "1", "test", EffectStage::BeforeLighting, {}, {}, ""};
  }
  std::vector<SettingDesc> settings() const override { return settings_; }
  void prepare(EffectContext&, const SettingValues&) override {}
  void addPasses(FrameGraph&, EffectContext&, const SettingValues&) override {}

 private:
  std::string name_;
  std::vector<SettingDesc> settings_;
};

TEST(Settings, RegistryRefusesBadDeclarationsAndTheEngineName) {
  EffectRegistry r;
  auto add = [&](const std::string& name, std::vector<SettingDesc> s) {
    return [&r, name, s] {
      r.add([name, s] { return std::make_unique<Declares>(name, s); }, "mod.so");
    };
  };
  expectError(add("bad_enum", {SettingDesc::enumeration("mode", {"x"}, 3, "h")}),
              ErrorKind::InvalidData, {"mod.so", "effect 'bad_enum'", "setting 'mode'"});
  expectError(add("bad_range", {{"v", SettingType::Float, 5, 0, 1, "h"}}), ErrorKind::InvalidData,
              {"mod.so", "effect 'bad_range'", "setting 'v'", "outside its range"});
  expectError(add("engine", {}), ErrorKind::InvalidData, {"mod.so", "'engine' is reserved"});
  EXPECT_TRUE(r.names().empty());
  add("good", allTypes())();
  EXPECT_EQ(r.defaultSettings("good").option("filter"), "tent");
  const std::string text = r.describe();
  for (const char* line :
       {"  good.filter (enum, default tent, options box, tent, gauss, changes the graph): "
        "filter kernel\n",
        "  good.offset (vec3, default [0, 1, -2], range [-10, 10] per component, uniform only)",
        "  good.tint (color, default [1, 0.5, 0.25], range [0, 4] per component",
        "  good.radius (float, default 0.5, range [0.0001, 10000], step 0.01, log scale, "
        "uniform only): world radius\n",
        "  good.samples (int, default 8, range [1, 64], changes the graph)"})
    EXPECT_NE(text.find(line), std::string::npos) << line << "\n" << text;
}

}  // namespace
}  // namespace gi
