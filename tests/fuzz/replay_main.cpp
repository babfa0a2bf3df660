// Without libFuzzer (the normal build): runs a fuzz target over every file of the folders (or
// files) given, so the corpus and every input that once crashed stay regression tests.
//
// With --mutate SECONDS [--seed N]: then, for that long, feeds the target mutations of those
// files (bit flips, interesting bytes and numbers, deleted, repeated and spliced ranges): a
// short, uninstrumented fuzz run that needs no second compiler or build tree, so the default
// suite fuzzes every parser for a few seconds (under ASan + UBSan in the asan preset).
// Coverage-guided fuzzing with libFuzzer stays in tools/fuzz. A crash, sanitizer report or hang
// (10 s) saves the input to $TMPDIR/gi-fuzz-finding-<pid>.bin and says so.
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);
// Present only under a sanitizer: called before the process dies of a report.
// NOLINTNEXTLINE(bugprone-reserved-identifier): the sanitizer runtime's own name
extern "C" void __sanitizer_set_death_callback(void (*callback)()) __attribute__((weak));

namespace {

namespace fs = std::filesystem;
using Bytes = std::vector<uint8_t>;

// The input being run, for the handlers below (async-signal-safe: write(2) only).
const Bytes* gCurrent = nullptr;
char gFindingPath[512] = {};

void writeAll(int fd, const void* data, size_t size) {
  const ssize_t written = ::write(fd, data, size);
  (void)written;  // nothing more can be done inside a dying process
}

void say(const char* text) {
  writeAll(2, text, std::strlen(text));
}

void saveFinding() {
  if (!gCurrent || !gFindingPath[0]) return;
  const int fd = ::open(gFindingPath, O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) return;
  writeAll(fd, gCurrent->data(), gCurrent->size());
  ::close(fd);
  say("\nfuzz_replay: finding: the input is saved to ");
  say(gFindingPath);
  say(" (commit it to tests/fuzz/regressions/<target>/ with the fix)\n");
  gCurrent = nullptr;
}

void onSignal(int sig) {
  saveFinding();
  if (sig == SIGALRM) say("fuzz_replay: an input ran for over 10 s (a hang)\n");
  std::signal(sig, SIG_DFL);
  std::raise(sig == SIGALRM ? SIGABRT : sig);
}

Bytes readFile(const fs::path& f) {
  std::ifstream in(f, std::ios::binary);
  return Bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void run(const Bytes& input) {
  gCurrent = &input;
  LLVMFuzzerTestOneInput(input.data(), input.size());
  gCurrent = nullptr;
}

// One random edit of `b` (`other`: another corpus file, for splicing).
void mutate(Bytes& b, const Bytes& other, std::mt19937_64& rng) {
  auto below = [&](size_t n) { return n == 0 ? size_t(0) : size_t(rng() % n); };
  static const char* kNumbers[] = {
      "0",           "-0",   "-1",     "1e309",      "-1e309",
      "nan",         "inf",  "1e-45",  "4294967296", "2147483648",
      "-2147483649", "1e38", "3.4e38", "0.0000001",  "99999999999999999999"};
  static const uint8_t kBytes[] = {0,   0xff, 0x7f, 0x80, '-',  '9', '"', '{',
                                   '}', '[',  ']',  ',',  '\n', ' ', '/', '.'};
  switch (below(7)) {
    case 0:  // flip a bit
      if (!b.empty()) b[below(b.size())] ^= uint8_t(1u << below(8));
      break;
    case 1:  // an interesting byte
      if (!b.empty()) b[below(b.size())] = kBytes[below(sizeof kBytes)];
      break;
    case 2: {  // delete a range
      if (b.empty()) break;
      const size_t at = below(b.size()), n = 1 + below(std::min<size_t>(64, b.size() - at));
      b.erase(b.begin() + long(at), b.begin() + long(at + n));
      break;
    }
    case 3: {  // repeat a range
      if (b.empty() || b.size() > (1u << 20)) break;
      const size_t at = below(b.size()), n = 1 + below(std::min<size_t>(256, b.size() - at));
      const Bytes piece(b.begin() + long(at), b.begin() + long(at + n));
      b.insert(b.begin() + long(below(b.size() + 1)), piece.begin(), piece.end());
      break;
    }
    case 4: {  // replace a run of digits by an extreme number
      if (b.empty()) break;
      size_t at = below(b.size());
      while (at < b.size() && !(b[at] >= '0' && b[at] <= '9')) ++at;
      if (at == b.size()) break;
      size_t end = at;
      while (end < b.size() && ((b[end] >= '0' && b[end] <= '9') || b[end] == '.')) ++end;
      const char* n = kNumbers[below(std::size(kNumbers))];
      b.erase(b.begin() + long(at), b.begin() + long(end));
      b.insert(b.begin() + long(at), n, n + std::strlen(n));
      break;
    }
    case 5: {  // splice: the head of this file, the tail of another
      if (other.empty()) break;
      const size_t cut = below(b.size() + 1), from = below(other.size());
      b.resize(cut);
      b.insert(b.end(), other.begin() + long(from), other.end());
      break;
    }
    default:  // truncate
      b.resize(below(b.size() + 1));
      break;
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<fs::path> files;
  double mutateSeconds = 0;
  uint64_t seed = uint64_t(std::chrono::steady_clock::now().time_since_epoch().count());
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--mutate" && i + 1 < argc) {
      mutateSeconds = std::atof(argv[++i]);
      continue;
    }
    if (a == "--seed" && i + 1 < argc) {
      seed = std::strtoull(argv[++i], nullptr, 10);
      continue;
    }
    std::error_code ec;
    if (fs::is_directory(a, ec)) {
      for (const auto& e : fs::recursive_directory_iterator(a))
        if (e.is_regular_file()) files.push_back(e.path());
    } else if (fs::is_regular_file(a, ec)) {
      files.push_back(a);
    }
  }
  std::sort(files.begin(), files.end());
  std::vector<Bytes> inputs;
  inputs.reserve(files.size());
  for (const fs::path& f : files) inputs.push_back(readFile(f));

  std::snprintf(gFindingPath, sizeof gFindingPath, "%s/gi-fuzz-finding-%d.bin",
                fs::temp_directory_path().c_str(), int(::getpid()));
  for (int sig : {SIGSEGV, SIGABRT, SIGBUS, SIGFPE, SIGILL, SIGALRM}) std::signal(sig, onSignal);
  if (__sanitizer_set_death_callback) __sanitizer_set_death_callback(saveFinding);

  for (const Bytes& input : inputs) run(input);
  std::printf("replayed %zu inputs\n", inputs.size());
  if (inputs.empty()) return 1;  // an empty corpus means a wrong path, not a pass
  if (mutateSeconds <= 0) return 0;

  std::printf("mutating for %.3g s, seed %llu (--seed reproduces the run)\n", mutateSeconds,
              static_cast<unsigned long long>(seed));
  std::fflush(stdout);
  std::mt19937_64 rng(seed);
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(mutateSeconds);
  size_t executions = 0;
  while (std::chrono::steady_clock::now() < end) {
    Bytes b = inputs[rng() % inputs.size()];
    const Bytes& other = inputs[rng() % inputs.size()];
    for (int n = 1 + int(rng() % 8); n > 0; --n) mutate(b, other, rng);
    ::alarm(10);
    run(b);
    ::alarm(0);
    ++executions;
  }
  std::printf("%zu mutated inputs, no finding\n", executions);
  return 0;
}
