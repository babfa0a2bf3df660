// What the command-line apps (gi-render, gi-reference, gi-bench) share: the argument loop,
// strict numbers, lists, output checks, atomic writes and the error convention of main() (one
// line naming the app, the error kind, the file or flag and the problem; exit 2 for usage
// errors, else 1).
#pragma once

#include <cstdint>
#include <cstdio>
#include <exception>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "gi/effect_config.h"
#include "gi/errors.h"

namespace gi::cli {

// A number as it would be written in source: shortest round-trip form (16384, 1e-09, 0.5).
std::string formatNumber(double v);

// Strict parsing. Decimal only: no hex (0x20), no inf/nan, no leading space, no trailing
// characters; a leading '+' is allowed. On failure `problem` says why ("is not a number",
// "is not an integer", "is out of range ...").
std::optional<double> parseDouble(std::string_view text, std::string* problem = nullptr);
std::optional<int64_t> parseInteger(std::string_view text, std::string* problem = nullptr);

// "a,b,c" -> {a, b, c}. Empty items are refused (usage error naming `flag`), as are duplicates
// unless `allowDuplicates`. An empty `text` gives an empty list.
std::vector<std::string> splitList(const std::string& flag, const std::string& text,
                                   bool allowDuplicates = false);

// Throws a usage error "<where>: <message> (see <app> --help)"; `where` may be empty.
[[noreturn]] void usageError(const std::string& app, const std::string& where,
                             const std::string& message);

// The argument loop: for (Args a(app, argc, argv, usage); a.next();) if (a.is("--width")) ...
// With a `usage` text, --help and -h print it and exit 0.
class Args {
 public:
  Args(const char* app, int argc, char** argv, const char* usage = nullptr)
      : app_(app), usage_(usage), argc_(argc), argv_(argv) {}
  bool next();
  const std::string& flag() const { return flag_; }
  bool is(std::string_view name) const { return flag_ == name; }
  // The flag's value (the next argument); usage error when there is none.
  const char* value();
  // The value as a number in [lo, hi] / an integer in [lo, hi]; usage errors say the range as
  // written: "--width: expects an integer in [1, 16384], got '1.5'".
  double number(double lo, double hi);
  int64_t integer(int64_t lo, int64_t hi);
  // A number > lo (open below) and <= hi: "expects a number in (0, 1e+09]".
  double numberAbove(double lo, double hi);
  std::vector<std::string> list(bool allowDuplicates = false) {
    return splitList(flag_, value(), allowDuplicates);
  }
  // --effects: a list of effect names, where "none" (as in gi-bench) and "" are the engine alone.
  std::vector<std::string> effectList() {
    const std::string text = value();
    return text == "none" ? std::vector<std::string>{} : splitList(flag_, text);
  }
  [[noreturn]] void fail(const std::string& message) const { usageError(app_, flag_, message); }
  [[noreturn]] void unknown() const;
  const char* app() const { return app_; }

 private:
  const char* app_;
  const char* usage_;
  int argc_;
  char** argv_;
  int i_ = 0;
  std::string flag_;
};

// The flags the rendering apps share, parsed in one place (parseCommonFlag). An app sets its
// defaults (size, validation from GI_VALIDATION) before the loop.
struct CommonFlags {
  std::string scene;                   // --scene FILE|default
  uint32_t width = 640, height = 480;  // --width, --height
  uint32_t minSize = 1;                // the smallest size the app accepts
  RenderRequest request;               // --preset, --effects, --set, --view
  std::string device;                  // --device NAME|INDEX (empty: GI_DEVICE or the first)
  bool validation = false;             // --validation
};
// Which groups of common flags an app takes.
enum CommonFlagGroup : unsigned {
  kSceneFlags = 1,   // --scene
  kSizeFlags = 2,    // --width, --height
  kEffectFlags = 4,  // --preset, --effects, --set, --view
  kDeviceFlags = 8,  // --device, --validation
  kAllCommonFlags = 15,
};
// True when the argument at `a` is one of the common flags in `groups`: its value is read (and
// checked) into `flags`. False for any other argument, which the app then parses.
bool parseCommonFlag(Args& a, CommonFlags& flags, unsigned groups = kAllCommonFlags);

// An output file that will be written later: its folder must be writable (or, when missing,
// its nearest existing ancestor: the writers make the missing folders) and the path must not be
// a folder. Checked before any work, so a long render never ends in "cannot write". Throws
// FileNotFound naming `path`.
void checkOutputWritable(const std::string& path);
// A folder that will be created or filled (gi-bench --out DIR): as checkOutputWritable for the
// folder's nearest existing ancestor; an existing non-folder is refused.
void checkOutputFolder(const std::string& dir);

// Writes `text` to `path` through `path`.partial and a rename: a failure leaves nothing behind
// (but the missing folders of `path`, made first).
void writeFileAtomic(const std::string& path, const std::string& text);

// Runs the app's body and turns exceptions into its one-line error and exit code.
template <class Body>
int runMain(const char* app, Body&& body) {
  try {
    return body();
  } catch (const Error& e) {
    std::fprintf(stderr, "%s: error (%s): %s\n", app, errorKindName(e.kind()), e.what());
    return e.kind() == ErrorKind::Usage ? 2 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: error: %s\n", app, e.what());
    return 1;
  } catch (...) {  // never terminate() with a core dump, whatever was thrown
    std::fprintf(stderr, "%s: error: an unexpected exception (not a std::exception)\n", app);
    return 1;
  }
}

}  // namespace gi::cli
