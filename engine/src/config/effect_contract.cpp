#include "gi/effect_contract.h"

#include <algorithm>
#include <map>

#include "gi/errors.h"

namespace gi {

namespace {
bool has(const std::vector<std::string>& v, const std::string& x) {
  return std::find(v.begin(), v.end(), x) != v.end();
}
}  // namespace

std::vector<size_t> orderEffects(const std::vector<const EffectInfo*>& effects) {
  auto dependsOn = [&](size_t b, size_t a) {  // does b run after a?
    for (const std::string& r : effects[a]->writes)
      if (!has(effects[a]->reads, r) && has(effects[b]->reads, r)) return true;
    return false;
  };
  std::vector<size_t> out;
  std::vector<bool> done(effects.size(), false);
  while (out.size() < effects.size()) {
    bool progressed = false;
    for (size_t i = 0; i < effects.size() && !progressed; ++i) {
      if (done[i]) continue;
      bool ready = true;
      for (size_t j = 0; j < effects.size() && ready; ++j)
        if (j != i && !done[j] && dependsOn(i, j)) ready = false;
      if (ready) {
        done[i] = true;
        out.push_back(i);
        progressed = true;
      }
    }
    if (!progressed) {
      std::string names;
      for (size_t i = 0; i < effects.size(); ++i)
        if (!done[i]) names += (names.empty() ? "" : ", ") + effects[i]->name;
      throw Error(ErrorKind::Usage, "",
                  "effects " + names + " depend on each other's outputs (a cycle)");
    }
  }
  return out;
}

void checkEffectResources(const EffectInfo& info, const std::set<std::string>& lookedUp,
                          const std::set<std::string>& published,
                          const std::function<bool(const std::string&)>& optional) {
  for (const std::string& name : lookedUp)
    if (!has(info.reads, name) && !has(info.writes, name))
      throw Error(ErrorKind::Usage, "",
                  "effect '" + info.name + "' reads '" + name +
                      "', which its EffectInfo::reads does not declare");
  for (const std::string& name : published)
    if (!has(info.writes, name))
      throw Error(ErrorKind::Usage, "",
                  "effect '" + info.name + "' publishes '" + name +
                      "', which its EffectInfo::writes does not declare");
  // An effect may choose to add nothing at all, and to leave an optional input unpublished.
  if (!published.empty())
    for (const std::string& name : info.writes)
      if (!published.count(name) && !(optional && optional(name)))
        throw Error(ErrorKind::Usage, "",
                    "effect '" + info.name + "' declares it writes '" + name +
                        "' but published nothing under that name");
}

void checkComposition(const std::vector<EffectPublications>& inOrder,
                      const std::vector<Masking>& masks) {
  std::map<std::string, std::string> lastWriter;  // resource -> effect
  for (const EffectPublications& e : inOrder) {
    for (const std::string& name : e.published) {
      auto it = lastWriter.find(name);
      if (it != lastWriter.end() && it->second != e.effect && !e.lookedUp.count(name))
        throw Error(ErrorKind::Usage, "",
                    "effects '" + it->second + "' and '" + e.effect + "' both write '" + name +
                        "' and '" + e.effect + "' does not read it: '" + it->second +
                        "''s would be replaced and reach nothing; enable one of them");
    }
    for (const std::string& name : e.published) lastWriter[name] = e.effect;
  }
  for (const Masking& m : masks) {
    auto masker = lastWriter.find(m.resource), masked = lastWriter.find(m.masked);
    if (masker == lastWriter.end() || masked == lastWriter.end() ||
        masker->second == masked->second)
      continue;
    const auto by = std::find_if(inOrder.begin(), inOrder.end(),
                                 [&](const auto& e) { return e.effect == masker->second; });
    if (by->lookedUp.count(m.masked)) continue;  // it composes the two itself
    throw Error(ErrorKind::Usage, "",
                "effect '" + masker->second + "' writes '" + m.resource + "' (" + m.resourceDoes +
                    "), so '" + masked->second + "''s '" + m.masked + "' (" + m.maskedDoes +
                    ") would cost time and reach nothing; enable one of them");
  }
}

}  // namespace gi
