#include "gi/effect_registry.h"

#include <dlfcn.h>
#include <elf.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "gi/engine_settings.h"
#include "gi/errors.h"

namespace gi {

namespace fs = std::filesystem;

namespace {
// The module being loaded, so add() can name it as the origin of what it registers.
thread_local const std::string* currentModule = nullptr;

// dlopen() maps a module by what its ELF headers say; a file cut short (a build writing it, a
// truncated copy) makes the mapped pages past its end fault with SIGBUS on first use, in any
// process that scans the folder. Checked before dlopen: the headers must lie within the file.
void checkElfComplete(const std::string& file, const std::string& path) {
  std::error_code ec;
  const uintmax_t size = fs::file_size(file, ec);
  if (ec) throw Error(ErrorKind::FileNotFound, path, "cannot read the module: " + ec.message());
  std::ifstream in(file, std::ios::binary);
  Elf64_Ehdr eh{};
  if (!in.read(reinterpret_cast<char*>(&eh), sizeof eh) ||
      std::memcmp(eh.e_ident, ELFMAG, SELFMAG) != 0 || eh.e_ident[EI_CLASS] != ELFCLASS64)
    return;  // not a 64-bit ELF file: dlopen says what it is
  auto truncated = [&](uint64_t needed) {
    throw Error(ErrorKind::InvalidData, path,
                "truncated module: " + std::to_string(size) + " bytes, its headers need " +
                    std::to_string(needed) + " (still being written?)");
  };
  const uint64_t ph = eh.e_phoff + uint64_t(eh.e_phnum) * eh.e_phentsize;
  const uint64_t sh = eh.e_shoff + uint64_t(eh.e_shnum) * eh.e_shentsize;
  if (ph > size) truncated(ph);
  if (sh > size) truncated(sh);
  for (unsigned i = 0; i < eh.e_phnum; ++i) {
    Elf64_Phdr p{};
    in.seekg(std::streamoff(eh.e_phoff + uint64_t(i) * eh.e_phentsize));
    if (!in.read(reinterpret_cast<char*>(&p), sizeof p)) truncated(ph);
    if (p.p_type == PT_LOAD && p.p_offset + p.p_filesz > size) truncated(p.p_offset + p.p_filesz);
  }
}

bool validName(const std::string& n) {
  if (n.empty()) return false;
  for (char c : n)
    if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_')) return false;
  return true;
}
}  // namespace

void EffectRegistry::add(const Factory& factory, const std::string& origin) {
  const std::string from = currentModule ? *currentModule : origin;
  std::unique_ptr<Effect> probe = factory();
  Entry e;
  e.info = probe->info();
  e.settings = probe->settings();
  e.factory = factory;
  e.origin = from;
  if (!validName(e.info.name))
    throw Error(ErrorKind::InvalidData, from,
                "effect name '" + e.info.name + "' must be lower-case letters, digits and '_'");
  if (has(e.info.name))
    throw Error(ErrorKind::InvalidData, from,
                "duplicate effect '" + e.info.name + "' (already registered by " +
                    origin_or(e.info.name) + ")");
  // Presets, scenes and --set use this name for the engine's own settings.
  if (e.info.name == kEngineSettingsOwner)
    throw Error(ErrorKind::InvalidData, from,
                "effect name 'engine' is reserved for the engine's own settings");
  try {
    validateSettingDescs("effect '" + e.info.name + "'", e.settings);
  } catch (const Error& err) {
    throw Error(ErrorKind::InvalidData, from, err.what());
  }
  entries_.push_back(std::move(e));
}

std::string EffectRegistry::origin_or(const std::string& name) const {
  return has(name) ? origin(name) : "?";
}

void EffectRegistry::openAndRegister(const std::string& file, const std::string& path,
                                     const std::string& replaced) {
  checkElfComplete(file, path);
  void* handle = dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!handle)
    throw Error(ErrorKind::InvalidData, path, std::string("cannot load module: ") + dlerror());
  auto version = reinterpret_cast<GiEffectAbiVersionFn>(dlsym(handle, "gi_effect_abi_version"));
  auto registerFn = reinterpret_cast<GiRegisterEffectsFn>(dlsym(handle, "gi_register_effects"));
  if (!version || !registerFn) {
    dlclose(handle);
    throw Error(ErrorKind::InvalidData, path,
                "not an effect module (gi_effect_abi_version / gi_register_effects missing)");
  }
  if (version() != GI_EFFECT_ABI_VERSION) {
    const uint32_t theirs = version();
    dlclose(handle);
    throw Error(ErrorKind::Unsupported, path,
                "effect ABI version " + std::to_string(theirs) + " does not match the engine's " +
                    std::to_string(GI_EFFECT_ABI_VERSION) +
                    "; rebuild the module against this engine");
  }
  // Register into a scratch registry first so a failing module changes nothing.
  EffectRegistry scratch;
  for (const Entry& e : entries_)
    if (replaced.empty() || e.origin != replaced) scratch.entries_.push_back(e);
  // The handle stays open whatever happens: code from it may still be referenced. A module's
  // own exception (its constructor's, whatever its type) becomes an error naming the module.
  currentModule = &path;
  try {
    registerFn(scratch);
  } catch (const Error&) {
    currentModule = nullptr;
    throw;  // the registry's own refusals name the module already
  } catch (const std::exception& e) {
    currentModule = nullptr;
    throw Error(ErrorKind::InvalidData, path,
                std::string("the module failed while registering its effects: ") + e.what());
  } catch (...) {
    currentModule = nullptr;
    throw Error(ErrorKind::InvalidData, path,
                "the module failed while registering its effects (it threw something that is "
                "not a std::exception)");
  }
  currentModule = nullptr;
  entries_ = std::move(scratch.entries_);
}

void EffectRegistry::loadModule(const std::string& path) {
  const std::string canonical = fs::weakly_canonical(path).string();
  for (const Module& m : modules_)
    if (m.canonical == canonical)
      throw Error(ErrorKind::InvalidData, path, "module already loaded");
  openAndRegister(path, path, "");
  modules_.push_back({path, canonical});
}

std::vector<std::string> EffectRegistry::reloadModule(const std::string& path) {
  const std::string canonical = fs::weakly_canonical(path).string();
  const auto loaded = std::find_if(modules_.begin(), modules_.end(),
                                   [&](const Module& m) { return m.canonical == canonical; });
  if (loaded == modules_.end())
    throw Error(ErrorKind::Usage, path, "cannot reload a module that was never loaded");
  // dlopen() returns the already loaded object for a path it has seen, and maps a file that a
  // build may still be writing: a private copy, removed once mapped, avoids both. It sits next
  // to the module (the same $ORIGIN for the libraries beside it), named so that no scan takes it
  // for a module, or in the temporary folder when the module's folder is read-only.
  static int copies = 0;
  const std::string name = "." + fs::path(path).filename().string() + ".reload-" +
                           std::to_string(getpid()) + "-" + std::to_string(++copies);
  std::error_code ec;
  fs::path copy = fs::path(path).parent_path() / name;
  if (!fs::copy_file(path, copy, fs::copy_options::overwrite_existing, ec) || ec) {
    if (!fs::exists(path, ec))
      throw Error(ErrorKind::FileNotFound, path, "cannot read the module: it is gone");
    copy = fs::temp_directory_path(ec) / name;
    if (ec || !fs::copy_file(path, copy, fs::copy_options::overwrite_existing, ec) || ec)
      throw Error(ErrorKind::FileNotFound, path,
                  "cannot read the module" + (ec ? ": " + ec.message() : std::string()));
  }
  try {
    openAndRegister(copy.string(), loaded->path, loaded->path);
  } catch (...) {
    fs::remove(copy, ec);
    throw;
  }
  fs::remove(copy, ec);
  std::vector<std::string> names;
  for (const Entry& e : entries_)
    if (e.origin == loaded->path) names.push_back(e.info.name);
  std::sort(names.begin(), names.end());
  return names;
}

std::vector<std::string> EffectRegistry::modulePaths() const {
  std::vector<std::string> out;
  for (const Module& m : modules_) out.push_back(m.path);
  return out;
}

void EffectRegistry::scanDirectory(const std::string& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return;
  std::vector<fs::path> modules;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    std::error_code entryError;  // a dangling link or a link loop: not a module, no error
    if (entry.is_regular_file(entryError) && entry.path().extension() == ".so")
      modules.push_back(entry.path());
  }
  std::sort(modules.begin(),
            modules.end());  // deterministic order, so duplicates resolve the same way
  for (const fs::path& m : modules) {
    try {
      loadModule(m.string());
    } catch (const Error& e) {
      problems_.push_back(e.what());
      std::fprintf(stderr, "gi: warning: effect module refused: %s\n", e.what());
    }
  }
}

std::vector<std::string> EffectRegistry::defaultLocations() {
  std::vector<std::string> dirs;
  std::error_code ec;
  fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) dirs.push_back((exe.parent_path() / "plugins").string());
  if (const char* env = std::getenv("GI_PLUGIN_PATH")) {
    std::stringstream ss(env);
    std::string dir;
    while (std::getline(ss, dir, ':'))
      if (!dir.empty()) dirs.push_back(dir);
  }
  return dirs;
}

void EffectRegistry::scanDefaultLocations() {
  for (const std::string& d : defaultLocations()) scanDirectory(d);
}

bool EffectRegistry::has(const std::string& name) const {
  return std::any_of(entries_.begin(), entries_.end(),
                     [&](const Entry& e) { return e.info.name == name; });
}

std::vector<std::string> EffectRegistry::names() const {
  std::vector<std::string> out;
  for (const Entry& e : entries_) out.push_back(e.info.name);
  std::sort(out.begin(), out.end());
  return out;
}

const EffectRegistry::Entry& EffectRegistry::entry(const std::string& name) const {
  for (const Entry& e : entries_)
    if (e.info.name == name) return e;
  std::string known;
  for (const std::string& n : names()) known += (known.empty() ? "" : ", ") + n;
  throw Error(ErrorKind::Schema, "",
              "unknown effect '" + name +
                  "' (known: " + (known.empty() ? "none; no plugins found" : known) + ")");
}

const EffectInfo& EffectRegistry::info(const std::string& name) const {
  return entry(name).info;
}
std::string EffectRegistry::origin(const std::string& name) const {
  return entry(name).origin;
}
std::unique_ptr<Effect> EffectRegistry::create(const std::string& name) const {
  return entry(name).factory();
}
SettingValues EffectRegistry::defaultSettings(const std::string& name) const {
  const Entry& e = entry(name);
  return SettingValues(e.info.name, e.settings);
}

std::string describe(const EstimatedQuantity& q) {
  auto num = [](double v) {
    char b[32];
    std::snprintf(b, sizeof b, "%g", v);
    return std::string(b);
  };
  using K = EstimatedQuantity::Kind;
  switch (q.kind) {
    case K::AmbientOcclusion:
      return "ao(r=" + num(q.radius) + ")";
    case K::Obscurance:
      return "obscurance(r=" + num(q.radius) + ", membership=" + q.membership + ")";
    case K::Alchemy:
      return "alchemy(r=" + num(q.radius) + ", sigma=" + num(q.sigma) + ", u=" + num(q.u) +
             ", epsilon=" + num(q.epsilon) + ", contrast=" + num(q.contrast) + ")";
    case K::AlchemyDisk:
      return "alchemy-disk(r=" + num(q.radius) + ", sigma=" + num(q.sigma) + ", u=" + num(q.u) +
             ", epsilon=" + num(q.epsilon) + ", contrast=" + num(q.contrast) +
             ", bias=" + num(q.bias) + ")";
    case K::DirectLight:
      return "direct light";
    case K::DirectIndirect:
      return "direct+indirect light";
  }
  return "unknown";
}

std::string EffectRegistry::describe() const {
  std::ostringstream s;
  if (entries_.empty()) s << "no effects found (searched:";
  if (entries_.empty())
    for (const std::string& d : defaultLocations()) s << " " << d;
  if (entries_.empty()) s << ")\n";
  for (const std::string& name : names()) {
    const Entry& e = entry(name);
    s << e.info.name << " " << e.info.version << " - " << e.info.description << "\n";
    s << "  module: " << e.origin << "\n";
    s << "  stage: "
      << (e.info.stage == EffectStage::BeforeLighting ? "before lighting" : "after lighting");
    std::string reads, writes;
    for (auto& r : e.info.reads) reads += " " + r;
    for (auto& w : e.info.writes) writes += " " + w;
    s << ", reads:" << (reads.empty() ? " -" : reads)
      << ", writes:" << (writes.empty() ? " -" : writes) << ", debug view: " << e.info.debugView
      << ", estimates: "
      << (e.info.estimates == GroundTruth::AmbientOcclusion ? "ambient occlusion"
          : e.info.estimates == GroundTruth::IndirectLight  ? "indirect light"
                                                            : "direct light")
      << "\n";
    // What its output is exactly, at its default settings (gi-bench's declared quantity).
    s << "  declares at its defaults: "
      << gi::describe(e.factory()->estimatedQuantity(SettingValues(e.info.name, e.settings)))
      << "\n";
    s << describeSettings(name, e.settings);
  }
  for (const std::string& p : problems_) s << "refused: " << p << "\n";
  return s.str();
}

}  // namespace gi
