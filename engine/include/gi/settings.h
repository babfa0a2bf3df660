// Typed effect settings: declared once by an effect (name, type, default, range, help, and
// whether a change rebuilds the frame graph), validated in one place, read back by name.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace gi {

enum class SettingType { Bool, Int, Float };

struct SettingDesc {
  std::string name;
  SettingType type = SettingType::Float;
  double defaultValue = 0.0;
  double minValue = 0.0, maxValue = 1.0;  // inclusive; ignored for Bool
  std::string help;
  bool changesGraph = false;  // false: uniform only, applied without recompiling the graph
};

// The current values of one effect's settings.
class SettingValues {
 public:
  SettingValues() = default;
  // Every setting at its default; `owner` (the effect's name) prefixes keys in messages.
  SettingValues(std::string owner, std::vector<SettingDesc> descs);

  // Sets a value from JSON (bool, integer or number as the setting's type requires).
  // `origin` names where the value came from (a file, "--set") for the error message.
  // Throws gi::Error(Schema) for an unknown key or wrong type, (InvalidData) out of range.
  void set(const std::string& key, const nlohmann::json& value, const std::string& origin);
  // Parses "32", "0.5", "true" for --set name=value.
  void setFromString(const std::string& key, const std::string& text, const std::string& origin);

  double number(const std::string& key) const;
  int integer(const std::string& key) const;
  bool flag(const std::string& key) const;
  const std::vector<SettingDesc>& descs() const { return descs_; }
  const SettingDesc& desc(const std::string& key) const;
  nlohmann::json toJson() const;
  // True when a setting that changes the graph differs between the two.
  bool graphDiffers(const SettingValues& other) const;

 private:
  std::string owner_;
  std::vector<SettingDesc> descs_;
  std::map<std::string, double> values_;
};

const char* settingTypeName(SettingType type);

}  // namespace gi
