// Typed settings: declared once by an effect (or the engine: gi/engine_settings.h) with name,
// type, default, range, help, UI hints and whether a change rebuilds the frame graph;
// validated in one place, read back by name.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <initializer_list>
#include <map>
#include <string>
#include <type_traits>
#include <vector>

#include <nlohmann/json.hpp>

namespace gi {

// Enum: one of named options (stored as the index). Vec3/Color: three numbers, each inside
// [minValue, maxValue] (Color: linear RGB, min 0).
enum class SettingType { Bool, Int, Float, Enum, Vec3, Color };

struct SettingDesc {
  std::string name;
  SettingType type = SettingType::Float;
  double defaultValue = 0.0;              // Enum: the default option's index
  double minValue = 0.0, maxValue = 1.0;  // inclusive; ignored for Bool and Enum
  std::string help;
  bool changesGraph = false;           // false: uniform only, applied without recompiling the graph
  std::vector<std::string> options{};  // Enum: the allowed names; value = index
  std::array<double, 3> defaultVector{};  // Vec3/Color default (min/max apply per component)
  double step = 0.0;                      // UI hint: widget step (0: type default)
  bool logScale = false;                  // UI hint: logarithmic slider (needs min > 0)
  // A length in world units (Float): for a model loaded without a scene file its default is
  // scaled by the model's size (Scene::lengthScale), so an AO radius fits a bunny or a city.
  bool worldLength = false;
  // A count of samples (taps, directions, steps, slices...) on an Int: more costs more time
  // and buys accuracy. gi-bench --calibrate searches powers of two of these; UIs may group them.
  bool sampleCount = false;

  static SettingDesc enumeration(std::string name, std::vector<std::string> options,
                                 int defaultIndex, std::string help, bool changesGraph = false);
  // A Float length in world units (worldLength set).
  static SettingDesc length(std::string name, double def, double min, double max, std::string help,
                            bool changesGraph = false);
  // An Int count of samples (sampleCount set).
  static SettingDesc samples(std::string name, int def, int min, int max, std::string help,
                             bool changesGraph = false);
  static SettingDesc vec3(std::string name, std::array<double, 3> def, double min, double max,
                          std::string help, bool changesGraph = false);
  static SettingDesc color(std::string name, std::array<double, 3> def, std::string help,
                           double max = 1.0, bool changesGraph = false);  // min 0
};

// Checks declarations: unique non-empty names, finite ranges with min <= max, defaults inside
// them (per component for vectors), enum options non-empty and unique with the default index
// in range, logScale only on numbers with min > 0, step >= 0. Throws gi::Error(InvalidData)
// "OWNER: setting 'NAME': problem".
void validateSettingDescs(const std::string& owner, const std::vector<SettingDesc>& descs);

// The current values of one owner's settings (an effect, or "engine").
// A setting found once by name (its place in the effect's declaration) and then read without a
// string look-up: make it with SettingValues::handle<T>(name) in prepare(), read it with
// values[handle] every frame. T: double (Float, Int, Bool, Enum index), int (Int, Enum index)
// or bool (Bool).
template <class T>
struct Setting {
  size_t index = size_t(-1);
};

class SettingValues {
 public:
  SettingValues() = default;
  // Every setting at its default; `owner` (the effect's name) prefixes keys in messages.
  SettingValues(std::string owner, std::vector<SettingDesc> descs);

  // Sets a value from JSON: bool, integer or number as the type requires; an Enum's option
  // name as a string; a Vec3/Color as [x, y, z]. `origin` names where the value came from (a
  // file, "--set") for the error message. Throws gi::Error(Schema) for an unknown key, wrong
  // type or arity, or unknown option (listing the options), (InvalidData) out of range or
  // non-finite (naming the component of a vector).
  void set(const std::string& key, const nlohmann::json& value, const std::string& origin);
  // Parses "32", "0.5", "true", an option name, "x,y,z" or "[x,y,z]" for --set name=value.
  void setFromString(const std::string& key, const std::string& text, const std::string& origin);

  double number(const std::string& key) const;  // Enum: the index; Vec3/Color: throws
  int integer(const std::string& key) const;    // Enum: the index
  bool flag(const std::string& key) const;
  const std::string& option(const std::string& key) const;     // Enum only: the name
  std::array<double, 3> vector(const std::string& key) const;  // Vec3/Color only
  // A typed handle to `key` (throws for an unknown key or a type T cannot hold).
  template <class T>
  Setting<T> handle(const std::string& key) const {
    if constexpr (std::is_same_v<T, bool>)
      typed(key, {SettingType::Bool}, "a bool");
    else if constexpr (std::is_same_v<T, int>)
      typed(key, {SettingType::Int, SettingType::Enum}, "an int");
    else
      typed(key, {SettingType::Bool, SettingType::Int, SettingType::Float, SettingType::Enum},
            "a number");
    return {index(key)};
  }
  template <class T>
  T operator[](Setting<T> h) const {
    handleDesc(h.index, "typed");
    const double v = values_[h.index][0];
    if constexpr (std::is_same_v<T, bool>)
      return v != 0.0;
    else if constexpr (std::is_same_v<T, int>)
      return int(std::lround(v));
    else
      return v;
  }
  const std::string& owner() const { return owner_; }
  const std::vector<SettingDesc>& descs() const { return descs_; }
  const SettingDesc& desc(const std::string& key) const;
  // Bool as true/false, Int as an integer, Enum as its name, Vec3/Color as [x, y, z].
  nlohmann::json toJson() const;
  // True when a setting that changes the graph differs between the two.
  bool graphDiffers(const SettingValues& other) const;
  // Takes `previous`'s value of every setting declared here with the same name and type that
  // this declaration accepts (in range, a known option): a rebuilt plugin keeps what the user
  // set. The others keep their values here. Returns the keys taken over.
  std::vector<std::string> adopt(const SettingValues& previous);

 private:
  const SettingDesc& typed(const std::string& key, std::initializer_list<SettingType> types,
                           const char* what) const;
  size_t index(const std::string& key) const;  // throws for an unknown key
  const SettingDesc& handleDesc(size_t index, const char* type) const;
  std::string owner_;
  std::vector<SettingDesc> descs_;
  std::vector<std::array<double, 3>> values_;  // per desc; scalars (and enum index) in [0]
};

const char* settingTypeName(SettingType type);
// One line per setting, as gi-render --list-effects prints them:
//   "  OWNER.NAME (float, default 0.5, range [0, 1], log scale, uniform only): help"
std::string describeSettings(const std::string& owner, const std::vector<SettingDesc>& descs);

}  // namespace gi
