#include "gi/settings.h"

#include <cmath>
#include <sstream>

#include "gi/errors.h"

namespace gi {

const char* settingTypeName(SettingType type) {
  switch (type) {
    case SettingType::Bool:
      return "bool";
    case SettingType::Int:
      return "int";
    case SettingType::Float:
      return "float";
  }
  return "?";
}

SettingValues::SettingValues(std::string owner, std::vector<SettingDesc> descs)
    : owner_(std::move(owner)), descs_(std::move(descs)) {
  for (const SettingDesc& d : descs_) {
    if (values_.count(d.name))
      throw Error(ErrorKind::Schema, "", owner_ + ": setting '" + d.name + "' declared twice");
    values_[d.name] = d.defaultValue;
  }
}

const SettingDesc& SettingValues::desc(const std::string& key) const {
  for (const SettingDesc& d : descs_)
    if (d.name == key) return d;
  std::string known;
  for (const SettingDesc& d : descs_) known += (known.empty() ? "" : ", ") + d.name;
  throw Error(ErrorKind::Schema, "",
              owner_ + "." + key + ": unknown setting (" + owner_ + " has: " + known + ")");
}

namespace {
std::string rangeText(const SettingDesc& d) {
  std::ostringstream s;
  if (d.type == SettingType::Bool) return "true or false";
  s << (d.type == SettingType::Int ? "an integer" : "a number") << " in [" << d.minValue << ", "
    << d.maxValue << "]";
  return s.str();
}
}  // namespace

void SettingValues::set(const std::string& key, const nlohmann::json& value,
                        const std::string& origin) {
  const SettingDesc* d = nullptr;
  try {
    d = &desc(key);
  } catch (const Error& e) {
    throw Error(ErrorKind::Schema, origin, e.what());
  }
  const std::string where = owner_ + "." + key;
  auto fail = [&](ErrorKind kind) {
    throw Error(kind, origin, where + ": expected " + rangeText(*d) + ", got " + value.dump());
  };
  double v = 0.0;
  switch (d->type) {
    case SettingType::Bool:
      if (!value.is_boolean()) fail(ErrorKind::Schema);
      v = value.get<bool>() ? 1.0 : 0.0;
      break;
    case SettingType::Int:
      if (!value.is_number_integer() &&
          !(value.is_number_float() && std::trunc(value.get<double>()) == value.get<double>()))
        fail(ErrorKind::Schema);
      v = value.get<double>();
      break;
    case SettingType::Float:
      if (!value.is_number()) fail(ErrorKind::Schema);
      v = value.get<double>();
      break;
  }
  if (!std::isfinite(v)) fail(ErrorKind::InvalidData);
  if (d->type != SettingType::Bool && (v < d->minValue || v > d->maxValue))
    fail(ErrorKind::InvalidData);
  values_[key] = v;
}

void SettingValues::setFromString(const std::string& key, const std::string& text,
                                  const std::string& origin) {
  nlohmann::json value = nlohmann::json::parse(text, nullptr, false);
  if (value.is_discarded()) value = text;  // reported as a wrong type by set()
  set(key, value, origin);
}

double SettingValues::number(const std::string& key) const {
  desc(key);
  return values_.at(key);
}
int SettingValues::integer(const std::string& key) const {
  return int(std::lround(number(key)));
}
bool SettingValues::flag(const std::string& key) const {
  return number(key) != 0.0;
}

nlohmann::json SettingValues::toJson() const {
  nlohmann::json j = nlohmann::json::object();
  for (const SettingDesc& d : descs_) {
    const double v = values_.at(d.name);
    if (d.type == SettingType::Bool)
      j[d.name] = v != 0.0;
    else if (d.type == SettingType::Int)
      j[d.name] = std::lround(v);
    else
      j[d.name] = v;
  }
  return j;
}

bool SettingValues::graphDiffers(const SettingValues& other) const {
  for (const SettingDesc& d : descs_)
    if (d.changesGraph && other.values_.count(d.name) &&
        other.values_.at(d.name) != values_.at(d.name))
      return true;
  return false;
}

}  // namespace gi
