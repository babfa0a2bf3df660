#include "gi/settings.h"

#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <set>
#include <sstream>

#include "gi/errors.h"

namespace gi {

using nlohmann::json;

const char* settingTypeName(SettingType type) {
  switch (type) {
    case SettingType::Bool:
      return "bool";
    case SettingType::Int:
      return "int";
    case SettingType::Float:
      return "float";
    case SettingType::Enum:
      return "enum";
    case SettingType::Vec3:
      return "vec3";
    case SettingType::Color:
      return "color";
  }
  return "?";
}

SettingDesc SettingDesc::enumeration(std::string name, std::vector<std::string> options,
                                     int defaultIndex, std::string help, bool changesGraph) {
  SettingDesc d;
  d.name = std::move(name);
  d.type = SettingType::Enum;
  d.defaultValue = defaultIndex;
  d.minValue = 0;
  d.maxValue = options.empty() ? 0 : double(options.size() - 1);
  d.help = std::move(help);
  d.changesGraph = changesGraph;
  d.options = std::move(options);
  return d;
}

SettingDesc SettingDesc::length(std::string name, double def, double min, double max,
                                std::string help, bool changesGraph) {
  SettingDesc d;
  d.name = std::move(name);
  d.type = SettingType::Float;
  d.defaultValue = def;
  d.minValue = min;
  d.maxValue = max;
  d.help = std::move(help);
  d.changesGraph = changesGraph;
  d.worldLength = true;
  return d;
}

SettingDesc SettingDesc::samples(std::string name, int def, int min, int max, std::string help,
                                 bool changesGraph) {
  SettingDesc d;
  d.name = std::move(name);
  d.type = SettingType::Int;
  d.defaultValue = def;
  d.minValue = min;
  d.maxValue = max;
  d.help = std::move(help);
  d.changesGraph = changesGraph;
  d.sampleCount = true;
  return d;
}

SettingDesc SettingDesc::vec3(std::string name, std::array<double, 3> def, double min, double max,
                              std::string help, bool changesGraph) {
  SettingDesc d;
  d.name = std::move(name);
  d.type = SettingType::Vec3;
  d.minValue = min;
  d.maxValue = max;
  d.help = std::move(help);
  d.changesGraph = changesGraph;
  d.defaultVector = def;
  return d;
}

SettingDesc SettingDesc::color(std::string name, std::array<double, 3> def, std::string help,
                               double max, bool changesGraph) {
  SettingDesc d = vec3(std::move(name), def, 0.0, max, std::move(help), changesGraph);
  d.type = SettingType::Color;
  return d;
}

namespace {

bool isVector(SettingType t) {
  return t == SettingType::Vec3 || t == SettingType::Color;
}

// 10 significant digits: 16777216 reads as such, not 1.67772e+07.
std::string num(double v) {
  std::ostringstream s;
  s << std::setprecision(10) << v;
  return s.str();
}

std::string vecText(const std::array<double, 3>& v) {
  std::ostringstream s;  // (not "[" + ...: GCC 12 reports a false -Wrestrict there)
  s << std::setprecision(10) << "[" << v[0] << ", " << v[1] << ", " << v[2] << "]";
  return s.str();
}

std::string optionList(const SettingDesc& d) {
  std::string s;
  for (const std::string& o : d.options) s += (s.empty() ? "" : ", ") + o;
  return s;
}

std::string rangeText(const SettingDesc& d) {
  switch (d.type) {
    case SettingType::Bool:
      return "true or false";
    case SettingType::Enum:
      return "one of: " + optionList(d);
    case SettingType::Vec3:
    case SettingType::Color:
      return "[x, y, z] with each component in [" + num(d.minValue) + ", " + num(d.maxValue) + "]";
    case SettingType::Int:
      return "an integer in [" + num(d.minValue) + ", " + num(d.maxValue) + "]";
    case SettingType::Float:
      break;
  }
  return "a number in [" + num(d.minValue) + ", " + num(d.maxValue) + "]";
}

const char* componentName(SettingType t, size_t i) {
  static const char* xyz[] = {"x", "y", "z"};
  static const char* rgb[] = {"r", "g", "b"};
  return t == SettingType::Color ? rgb[i] : xyz[i];
}

void checkDesc(const SettingDesc& d) {
  auto fail = [&](const std::string& problem) {
    throw Error(ErrorKind::InvalidData, "", "setting '" + d.name + "': " + problem);
  };
  if (d.name.empty()) throw Error(ErrorKind::InvalidData, "", "a setting has an empty name");
  if (!std::isfinite(d.step) || d.step < 0) fail("step must be >= 0");
  if (d.type != SettingType::Enum && !d.options.empty()) fail("options are only for enum settings");
  if (d.type == SettingType::Bool) {
    if (d.defaultValue != 0.0 && d.defaultValue != 1.0) fail("bool default must be 0 or 1");
    if (d.logScale) fail("logScale needs a numeric setting");
    return;
  }
  if (d.type == SettingType::Enum) {
    if (d.options.empty()) fail("an enum needs at least one option");
    std::set<std::string> seen;
    for (const std::string& o : d.options) {
      if (o.empty()) fail("empty option name");
      if (!seen.insert(o).second) fail("option '" + o + "' listed twice");
    }
    if (std::trunc(d.defaultValue) != d.defaultValue || d.defaultValue < 0 ||
        d.defaultValue >= double(d.options.size()))
      fail("default index " + num(d.defaultValue) + " is not an option index (0.." +
           std::to_string(d.options.size() - 1) + ")");
    if (d.logScale) fail("logScale needs a numeric setting");
    return;
  }
  if (!std::isfinite(d.minValue) || !std::isfinite(d.maxValue) || d.minValue > d.maxValue)
    fail("range [" + num(d.minValue) + ", " + num(d.maxValue) + "] is empty or not finite");
  if (d.logScale && !(d.minValue > 0)) fail("logScale needs min > 0");
  if (d.worldLength && d.type != SettingType::Float) fail("worldLength needs a float setting");
  if (d.sampleCount && d.type != SettingType::Int) fail("sampleCount needs an int setting");
  auto inRange = [&](double v) { return std::isfinite(v) && d.minValue <= v && v <= d.maxValue; };
  if (isVector(d.type)) {
    for (size_t i = 0; i < 3; ++i)
      if (!inRange(d.defaultVector[i]))
        fail("default " + vecText(d.defaultVector) + " is outside its range (component " +
             componentName(d.type, i) + ")");
    return;
  }
  if (!inRange(d.defaultValue)) fail("default is outside its range");
  if (d.type == SettingType::Int && std::trunc(d.defaultValue) != d.defaultValue)
    fail("int default must be an integer");
}

}  // namespace

void validateSettingDescs(const std::string& owner, const std::vector<SettingDesc>& descs) {
  std::set<std::string> names;
  for (const SettingDesc& d : descs) {
    try {
      checkDesc(d);
    } catch (const Error& e) {
      throw Error(ErrorKind::InvalidData, "", owner + ": " + e.what());
    }
    if (!names.insert(d.name).second)
      throw Error(ErrorKind::InvalidData, "", owner + ": setting '" + d.name + "' declared twice");
  }
}

SettingValues::SettingValues(std::string owner, std::vector<SettingDesc> descs)
    : owner_(std::move(owner)), descs_(std::move(descs)) {
  std::set<std::string> names;
  for (const SettingDesc& d : descs_) {
    if (!names.insert(d.name).second)
      throw Error(ErrorKind::Schema, "", owner_ + ": setting '" + d.name + "' declared twice");
    values_.push_back(isVector(d.type) ? d.defaultVector
                                       : std::array<double, 3>{d.defaultValue, 0.0, 0.0});
  }
}

size_t SettingValues::index(const std::string& key) const {
  return size_t(&desc(key) - descs_.data());
}

const SettingDesc& SettingValues::handleDesc(size_t index, const char* type) const {
  if (index >= descs_.size())
    throw Error(ErrorKind::Schema, "",
                owner_ + ": a " + type + " setting handle made for another declaration");
  return descs_[index];
}

const SettingDesc& SettingValues::desc(const std::string& key) const {
  for (const SettingDesc& d : descs_)
    if (d.name == key) return d;
  std::string known;
  for (const SettingDesc& d : descs_) known += (known.empty() ? "" : ", ") + d.name;
  throw Error(ErrorKind::Schema, "",
              owner_ + "." + key + ": unknown setting (" + owner_ + " has: " + known + ")");
}

const SettingDesc& SettingValues::typed(const std::string& key,
                                        std::initializer_list<SettingType> types,
                                        const char* what) const {
  const SettingDesc& d = desc(key);
  for (SettingType t : types)
    if (d.type == t) return d;
  throw Error(ErrorKind::Schema, "",
              owner_ + "." + key + ": is " + settingTypeName(d.type) + ", not " + what);
}

void SettingValues::set(const std::string& key, const json& value, const std::string& origin) {
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
  std::array<double, 3> v{};
  switch (d->type) {
    case SettingType::Bool:
      if (!value.is_boolean()) fail(ErrorKind::Schema);
      v[0] = value.get<bool>() ? 1.0 : 0.0;
      break;
    case SettingType::Int:
      if (!value.is_number_integer() &&
          !(value.is_number_float() && std::trunc(value.get<double>()) == value.get<double>()))
        fail(ErrorKind::Schema);
      v[0] = value.get<double>();
      break;
    case SettingType::Float:
      if (!value.is_number()) fail(ErrorKind::Schema);
      v[0] = value.get<double>();
      break;
    case SettingType::Enum: {
      if (!value.is_string()) fail(ErrorKind::Schema);
      const std::string name = value.get<std::string>();
      size_t i = 0;
      while (i < d->options.size() && d->options[i] != name) ++i;
      if (i == d->options.size())
        throw Error(ErrorKind::Schema, origin,
                    where + ": unknown option '" + name + "' (one of: " + optionList(*d) + ")");
      values_[index(key)] = {double(i), 0.0, 0.0};
      return;
    }
    case SettingType::Vec3:
    case SettingType::Color: {
      if (!value.is_array() || value.size() != 3)
        throw Error(ErrorKind::Schema, origin,
                    where + ": expected 3 components " + rangeText(*d) + ", got " + value.dump());
      for (size_t i = 0; i < 3; ++i) {
        const std::string comp =
            where + ": component " + std::to_string(i) + " (" + componentName(d->type, i) + ")";
        if (!value[i].is_number())
          throw Error(ErrorKind::Schema, origin,
                      comp + ": expected a number, got " + value[i].dump());
        v[i] = value[i].get<double>();
        if (!std::isfinite(v[i]) || v[i] < d->minValue || v[i] > d->maxValue)
          throw Error(ErrorKind::InvalidData, origin,
                      comp + ": expected a finite number in [" + num(d->minValue) + ", " +
                          num(d->maxValue) + "], got " + num(v[i]));
      }
      values_[index(key)] = v;
      return;
    }
  }
  if (!std::isfinite(v[0])) fail(ErrorKind::InvalidData);
  if (d->type != SettingType::Bool && (v[0] < d->minValue || v[0] > d->maxValue))
    fail(ErrorKind::InvalidData);
  values_[index(key)] = v;
}

namespace {
std::string trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t"), b = s.find_last_not_of(" \t");
  return a == std::string::npos ? "" : s.substr(a, b - a + 1);
}

// "x,y,z" or "[x,y,z]" -> a JSON array of what parses as numbers (strtod: "nan" and "inf" too,
// so set() reports them as non-finite); other components stay strings, reported as such.
json vectorFromText(const std::string& text) {
  std::string body = trim(text);
  if (body.size() >= 2 && body.front() == '[' && body.back() == ']')
    body = body.substr(1, body.size() - 2);
  json out = json::array();
  std::stringstream ss(body);
  std::string part;
  while (std::getline(ss, part, ',')) {
    part = trim(part);
    char* end = nullptr;
    const double v = std::strtod(part.c_str(), &end);
    if (!part.empty() && *end == '\0')
      out.push_back(v);
    else
      out.push_back(part);
  }
  if (!body.empty() && body.back() == ',') out.push_back("");  // "1,2," has 3 parts
  return out;
}
}  // namespace

void SettingValues::setFromString(const std::string& key, const std::string& text,
                                  const std::string& origin) {
  const SettingDesc* d = nullptr;
  try {
    d = &desc(key);
  } catch (const Error& e) {
    throw Error(ErrorKind::Schema, origin, e.what());
  }
  if (isVector(d->type)) return set(key, vectorFromText(text), origin);
  json value = json::parse(text, nullptr, false);
  if (value.is_discarded() || (d->type == SettingType::Enum && !value.is_string()))
    value = text;  // an option name as is; anything else is reported as a wrong type by set()
  set(key, value, origin);
}

double SettingValues::number(const std::string& key) const {
  typed(key, {SettingType::Bool, SettingType::Int, SettingType::Float, SettingType::Enum},
        "a number (use vector())");
  return values_[index(key)][0];
}
int SettingValues::integer(const std::string& key) const {
  return int(std::lround(number(key)));
}
bool SettingValues::flag(const std::string& key) const {
  return number(key) != 0.0;
}
const std::string& SettingValues::option(const std::string& key) const {
  const SettingDesc& d = typed(key, {SettingType::Enum}, "an enum");
  return d.options.at(size_t(values_[index(key)][0]));
}
std::array<double, 3> SettingValues::vector(const std::string& key) const {
  typed(key, {SettingType::Vec3, SettingType::Color}, "a vec3 or color");
  return values_[index(key)];
}

std::vector<std::string> SettingValues::adopt(const SettingValues& previous) {
  std::vector<std::string> taken;
  const json old = previous.toJson();
  for (const SettingDesc& d : descs_) {
    const auto same = std::find_if(previous.descs_.begin(), previous.descs_.end(),
                                   [&](const SettingDesc& p) { return p.name == d.name; });
    if (same == previous.descs_.end() || same->type != d.type) continue;
    try {
      set(d.name, old.at(d.name), "previous settings");
      taken.push_back(d.name);
    } catch (const Error&) {
      // Out of the new range or an option that no longer exists: the new default stays.
    }
  }
  return taken;
}

json SettingValues::toJson() const {
  json j = json::object();
  for (const SettingDesc& d : descs_) {
    const std::array<double, 3>& v = values_[size_t(&d - descs_.data())];
    switch (d.type) {
      case SettingType::Bool:
        j[d.name] = v[0] != 0.0;
        break;
      case SettingType::Int:
        j[d.name] = std::lround(v[0]);
        break;
      case SettingType::Float:
        j[d.name] = v[0];
        break;
      case SettingType::Enum:
        j[d.name] = d.options.at(size_t(v[0]));
        break;
      case SettingType::Vec3:
      case SettingType::Color:
        j[d.name] = {v[0], v[1], v[2]};
        break;
    }
  }
  return j;
}

bool SettingValues::graphDiffers(const SettingValues& other) const {
  for (size_t i = 0; i < descs_.size(); ++i) {
    if (!descs_[i].changesGraph) continue;
    for (size_t j = 0; j < other.descs_.size(); ++j)
      if (other.descs_[j].name == descs_[i].name && other.values_[j] != values_[i]) return true;
  }
  return false;
}

std::string describeSettings(const std::string& owner, const std::vector<SettingDesc>& descs) {
  std::ostringstream s;
  s << std::setprecision(10);
  for (const SettingDesc& d : descs) {
    s << "  " << owner << "." << d.name << " (" << settingTypeName(d.type) << ", default ";
    switch (d.type) {
      case SettingType::Bool:
        s << (d.defaultValue != 0.0 ? "true" : "false");
        break;
      case SettingType::Enum:
        s << (size_t(d.defaultValue) < d.options.size() ? d.options[size_t(d.defaultValue)] : "?")
          << ", options " << optionList(d);
        break;
      case SettingType::Vec3:
      case SettingType::Color:
        s << vecText(d.defaultVector) << ", range [" << d.minValue << ", " << d.maxValue
          << "] per component";
        break;
      case SettingType::Int:
      case SettingType::Float:
        s << d.defaultValue << ", range [" << d.minValue << ", " << d.maxValue << "]";
        break;
    }
    if (d.step > 0) s << ", step " << d.step;
    if (d.logScale) s << ", log scale";
    if (d.worldLength) s << ", world length (a bare model scales the default)";
    if (d.sampleCount) s << ", sample count";
    s << (d.changesGraph ? ", changes the graph" : ", uniform only") << "): " << d.help << "\n";
  }
  return s.str();
}

}  // namespace gi
