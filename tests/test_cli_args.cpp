// The command-line apps' shared parsing (apps/common/cli.h): integers are integers, numbers are
// decimal and finite, ranges are printed as written, lists refuse empty and repeated items,
// outputs are checked before any work and written atomically.
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cli.h"
#include "gi/image_io.h"
#include "test_support.h"

namespace gi {
namespace {

namespace fs = std::filesystem;

// Runs `f` expecting gi::Error of `kind`; returns its message.
std::string errorOf(const std::function<void()>& f, ErrorKind kind) {
  try {
    f();
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), kind) << e.what();
    return e.what();
  }
  ADD_FAILURE() << "no error";
  return {};
}

// Parses one flag with its value through cli::Args, as the apps do.
struct Parsed {
  std::vector<std::string> argv;
  std::vector<char*> ptrs;
  explicit Parsed(std::vector<std::string> a) : argv(std::move(a)) {
    argv.insert(argv.begin(), "app");
    for (std::string& s : argv) ptrs.push_back(s.data());
  }
  cli::Args args() { return cli::Args("gi-test", int(ptrs.size()), ptrs.data()); }
};

int64_t integerArg(const std::string& text, int64_t lo, int64_t hi) {
  Parsed p({"--width", text});
  cli::Args a = p.args();
  EXPECT_TRUE(a.next());
  return a.integer(lo, hi);
}

double numberArg(const std::string& text, double lo, double hi) {
  Parsed p({"--time", text});
  cli::Args a = p.args();
  EXPECT_TRUE(a.next());
  return a.number(lo, hi);
}

TEST(CliArgs, IntegersAreDecimalIntegers) {
  EXPECT_EQ(integerArg("640", 1, 16384), 640);
  EXPECT_EQ(integerArg("+16384", 1, 16384), 16384);
  const struct {
    const char* text;
    const char* why;
  } bad[] = {{"1.5", "which is not an integer"},
             {"2.0", "which is not an integer"},
             {"1e3", "which is not an integer"},
             {"0x20", "which is hexadecimal"},
             {"12abc", "which is not a number"},
             {" 12", "which is not a number"},
             {"", "which is not a number"},
             {"99999999999999999999", "which is out of range for an integer"},
             {"1e400", "which is out of range (beyond +-1.8e308"}};
  for (const auto& b : bad) {
    const std::string msg = errorOf([&] { integerArg(b.text, 1, 16384); }, ErrorKind::Usage);
    EXPECT_NE(msg.find("--width: expects an integer in [1, 16384], got '" + std::string(b.text) +
                       "', " + b.why),
              std::string::npos)
        << msg;
    EXPECT_NE(msg.find("(see gi-test --help)"), std::string::npos) << msg;
  }
  const std::string msg = errorOf([] { integerArg("0", 1, 16384); }, ErrorKind::Usage);
  EXPECT_NE(msg.find("--width: expects an integer in [1, 16384], got '0' ("), std::string::npos)
      << msg;
}

TEST(CliArgs, NumbersAreFiniteDecimalsAndRangesPrintAsWritten) {
  EXPECT_DOUBLE_EQ(numberArg("-2.5", -1e9, 1e9), -2.5);
  EXPECT_DOUBLE_EQ(numberArg("1e-500", 0, 1), 0.0);  // below the smallest double: zero
  for (const char* bad : {"inf", "nan", "-inf", "0x1p3", "1,5", "1.5x"})
    errorOf([&] { numberArg(bad, -1e9, 1e9); }, ErrorKind::Usage);
  std::string msg = errorOf([] { numberArg("1e400", -1e9, 1e9); }, ErrorKind::Usage);
  EXPECT_NE(msg.find("--time: expects a number in [-1e9, 1e9], got '1e400', which is out of "
                     "range (beyond +-1.8e308, the largest double)"),
            std::string::npos)
      << msg;
  msg = errorOf([] { numberArg("2", 1e-9, 1.5); }, ErrorKind::Usage);
  EXPECT_NE(msg.find("in [1e-9, 1.5], got '2'"), std::string::npos) << msg;
  EXPECT_EQ(msg.find("000000"), std::string::npos) << msg;
  // An open lower bound is printed open: 0 itself is outside.
  Parsed p({"--radius", "0"});
  cli::Args a = p.args();
  ASSERT_TRUE(a.next());
  msg = errorOf([&] { a.numberAbove(0, 1e9); }, ErrorKind::Usage);
  EXPECT_NE(msg.find("--radius: expects a number in (0, 1e9], got '0'"), std::string::npos) << msg;
}

TEST(CliArgs, FormatNumberIsTheShortestExactForm) {
  EXPECT_EQ(cli::formatNumber(16384), "16384");
  EXPECT_EQ(cli::formatNumber(0.5), "0.5");
  EXPECT_EQ(cli::formatNumber(1e9), "1e9");
  EXPECT_EQ(cli::formatNumber(1e-9), "1e-9");
  EXPECT_EQ(cli::formatNumber(-1e15), "-1e15");
  EXPECT_EQ(cli::formatNumber(double(1 << 24)), "16777216");
  EXPECT_EQ(cli::formatNumber(1.25e-5), "1.25e-5");
}

TEST(CliArgs, ArgumentLoopAndUsageErrors) {
  Parsed p({"--scene", "a.json", "--out"});
  cli::Args a = p.args();
  ASSERT_TRUE(a.next());
  EXPECT_TRUE(a.is("--scene"));
  EXPECT_STREQ(a.value(), "a.json");
  ASSERT_TRUE(a.next());
  EXPECT_TRUE(a.is("--out"));
  std::string msg = errorOf([&] { a.value(); }, ErrorKind::Usage);
  EXPECT_EQ(msg, "--out: needs a value (see gi-test --help)");
  EXPECT_FALSE(a.next());
  Parsed q({"--bogus"});
  cli::Args b = q.args();
  ASSERT_TRUE(b.next());
  msg = errorOf([&] { b.unknown(); }, ErrorKind::Usage);
  EXPECT_EQ(msg, "unknown argument '--bogus' (see gi-test --help)");
}

TEST(CliArgs, CommonFlagsAreParsedInOnePlace) {
  Parsed p({"--scene",
            "a.json",
            "--width",
            "320",
            "--height",
            "200",
            "--preset",
            "low",
            "--effects",
            "ssao,hbao",
            "--set",
            "ssao.radius=1",
            "--set",
            "engine.exposure=2",
            "--view",
            "ao",
            "--device",
            "1",
            "--validation",
            "--frames",
            "3"});
  cli::Args a = p.args();
  cli::CommonFlags f;
  std::vector<std::string> others;
  while (a.next())
    if (!cli::parseCommonFlag(a, f)) others.push_back(a.flag() + "=" + a.value());
  EXPECT_EQ(f.scene, "a.json");
  EXPECT_EQ(f.width, 320u);
  EXPECT_EQ(f.height, 200u);
  EXPECT_EQ(f.request.preset, "low");
  EXPECT_EQ(f.request.overrides.effects, (std::vector<std::string>{"ssao", "hbao"}));
  EXPECT_EQ(f.request.overrides.sets,
            (std::vector<std::string>{"ssao.radius=1", "engine.exposure=2"}));
  EXPECT_EQ(f.request.view, "ao");
  EXPECT_EQ(f.device, "1");
  EXPECT_TRUE(f.validation);
  EXPECT_EQ(others, std::vector<std::string>{"--frames=3"});  // not a common flag: the app's

  // A group the app does not take is left to it (and so is unknown there).
  Parsed q({"--preset", "low"});
  cli::Args b = q.args();
  ASSERT_TRUE(b.next());
  EXPECT_FALSE(cli::parseCommonFlag(b, f, cli::kSceneFlags | cli::kSizeFlags));
  // Sizes are checked against the app's smallest.
  Parsed r({"--width", "8"});
  cli::Args c = r.args();
  ASSERT_TRUE(c.next());
  f.minSize = 16;
  EXPECT_EQ(errorOf([&] { cli::parseCommonFlag(c, f); }, ErrorKind::Usage),
            "--width: expects an integer in [16, 16384], got '8' (see gi-test --help)");
  // --effects refuses a name twice, as before.
  Parsed t({"--effects", "ssao,ssao"});
  cli::Args d = t.args();
  ASSERT_TRUE(d.next());
  errorOf([&] { cli::parseCommonFlag(d, f); }, ErrorKind::Usage);
}

TEST(CliArgs, ListsRefuseEmptyAndRepeatedItems) {
  EXPECT_EQ(cli::splitList("--effects", "ssao,gtao"), (std::vector<std::string>{"ssao", "gtao"}));
  EXPECT_TRUE(cli::splitList("--effects", "").empty());
  std::string msg = errorOf([] { cli::splitList("--effects", "ssao,ssao"); }, ErrorKind::Usage);
  EXPECT_EQ(msg, "--effects: 'ssao' is listed twice in 'ssao,ssao'");
  msg = errorOf([] { cli::splitList("--effects", "ssao,,gtao"); }, ErrorKind::Usage);
  EXPECT_EQ(msg, "--effects: empty item in the list 'ssao,,gtao'");
  errorOf([] { cli::splitList("--effects", "ssao,"); }, ErrorKind::Usage);
  EXPECT_EQ(cli::splitList("--grid", "4,4", true).size(), 2u);
}

TEST(CliArgs, OutputsAreCheckedBeforeAnyWork) {
  test::TempDir dir("test_cli_args");
  const std::string ok = dir.path("x.png");
  cli::checkOutputWritable(ok);
  EXPECT_FALSE(fs::exists(ok)) << "the check leaves nothing behind";
  EXPECT_FALSE(fs::exists(ok + ".partial"));
  // A missing folder is made when the file is written: only its existing ancestor is checked.
  cli::checkOutputWritable(dir.path("nodir/deeper/x.png"));
  EXPECT_FALSE(fs::exists(dir.path("nodir"))) << "the check leaves nothing behind";
  std::string msg =
      errorOf([] { cli::checkOutputWritable("/sys/gi-nodir/x.png"); }, ErrorKind::Output);
  EXPECT_NE(msg.find("cannot write in the output folder /sys: "), std::string::npos) << msg;
  const std::string plain = dir.write("plain", "x");
  msg = errorOf([&] { cli::checkOutputWritable(plain + "/x.png"); }, ErrorKind::Output);
  EXPECT_NE(msg.find("is not a folder"), std::string::npos) << msg;
  fs::create_directories(dir.path("folder.png"));
  msg = errorOf([&] { cli::checkOutputWritable(dir.path("folder.png")); }, ErrorKind::Output);
  EXPECT_NE(msg.find("output path is a folder"), std::string::npos) << msg;
  // A folder that exists but cannot be written (also as root: /sys refuses new files).
  msg = errorOf([] { cli::checkOutputWritable("/sys/gi-test.png"); }, ErrorKind::Output);
  EXPECT_NE(msg.find("cannot write in the output folder /sys: "), std::string::npos) << msg;
  EXPECT_EQ(msg.find("does the folder exist"), std::string::npos) << msg;
  // Folders to be created: the nearest existing ancestor must be writable.
  cli::checkOutputFolder(dir.path("new/deeper"));
  EXPECT_FALSE(fs::exists(dir.path("new")));
  errorOf([] { cli::checkOutputFolder("/sys/gi-test-dir"); }, ErrorKind::Output);
  const std::string file = dir.write("file", "x");
  msg = errorOf([&] { cli::checkOutputFolder(file); }, ErrorKind::Output);
  EXPECT_NE(msg.find("exists and is not a folder"), std::string::npos) << msg;
}

TEST(CliArgs, OutputsNeverReplaceWhatIsNotARegularFile) {
  // A FIFO (as a device node would be) at an output path: refused before any work and again
  // at commit, by the text and the image writers alike; it stays a FIFO, nothing is left.
  test::TempDir dir("test_cli_args_fifo");
  const std::string fifo = dir.path("pipe.png");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  auto stillAFifo = [&] {
    EXPECT_TRUE(fs::is_fifo(fifo)) << "replaced";
    EXPECT_FALSE(fs::exists(fifo + ".partial"));
  };
  const std::string msg = errorOf([&] { cli::checkOutputWritable(fifo); }, ErrorKind::Output);
  EXPECT_NE(msg.find("not a regular file"), std::string::npos) << msg;
  errorOf([&] { cli::writeFileAtomic(fifo, "digraph {}\n"); }, ErrorKind::Output);
  stillAFifo();
  ImageRGBA8 image;
  image.width = image.height = 1;
  image.pixels = {1, 2, 3, 255};
  errorOf([&] { writePng(fifo, image); }, ErrorKind::Output);
  stillAFifo();
  // Through a symbolic link too; a link to a regular file is an ordinary output.
  const std::string link = dir.path("link.png");
  fs::create_symlink(fifo, link);
  errorOf([&] { cli::checkOutputWritable(link); }, ErrorKind::Output);
  stillAFifo();
  EXPECT_TRUE(fs::is_symlink(link));
  const std::string plain = dir.write("plain.png", "x"), plainLink = dir.path("plain_link.png");
  fs::create_symlink(plain, plainLink);
  cli::checkOutputWritable(plainLink);
}

TEST(CliArgs, OutputsNeverReplaceADeviceNode) {
  // A private character device (the null device's numbers) in a temporary folder, never the
  // system's: refused before any work and at commit; it stays a device node.
  test::TempDir dir("test_cli_args_node");
  const std::string node = dir.path("node.png");
  if (::mknod(node.c_str(), S_IFCHR | 0600, makedev(1, 3)) != 0)
    GTEST_SKIP() << "mknod is not permitted here: " << std::strerror(errno);
  const std::string msg = errorOf([&] { cli::checkOutputWritable(node); }, ErrorKind::Output);
  EXPECT_NE(msg.find("not a regular file"), std::string::npos) << msg;
  errorOf([&] { cli::writeFileAtomic(node, "digraph {}\n"); }, ErrorKind::Output);
  ImageRGBA8 image;
  image.width = image.height = 1;
  image.pixels = {1, 2, 3, 255};
  errorOf([&] { writePng(node, image); }, ErrorKind::Output);
  EXPECT_TRUE(fs::is_character_file(node)) << "replaced";
  EXPECT_FALSE(fs::exists(node + ".partial"));
}

TEST(CliArgs, AtomicWritesLeaveNothingOnFailure) {
  test::TempDir dir("test_cli_args_write");
  const std::string path = dir.path("a.txt");
  cli::writeFileAtomic(path, "hello");
  std::ifstream in(path);
  std::string text;
  std::getline(in, text);
  EXPECT_EQ(text, "hello");
  EXPECT_FALSE(fs::exists(path + ".partial"));
  // Missing folders are made; a folder that cannot be made fails and leaves no file.
  cli::writeFileAtomic(dir.path("nodir/deeper/a.txt"), "x");
  EXPECT_TRUE(fs::is_regular_file(dir.path("nodir/deeper/a.txt")));
  const std::string plain = dir.write("plain", "x");
  errorOf([&] { cli::writeFileAtomic(plain + "/a.txt", "x"); }, ErrorKind::Output);
  EXPECT_FALSE(fs::exists(plain + "/a.txt.partial"));
}

}  // namespace
}  // namespace gi
