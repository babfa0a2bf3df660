// Effect declarations without a device: the order effects of one stage run in, and the check of
// what an effect's passes looked up and published against what it declared.
#include <gtest/gtest.h>

#include "gi/effect_contract.h"
#include "gi/errors.h"
#include "test_support.h"

namespace gi {
namespace {

EffectInfo effect(const std::string& name, std::vector<std::string> reads,
                  std::vector<std::string> writes) {
  EffectInfo i;
  i.name = name;
  i.reads = std::move(reads);
  i.writes = std::move(writes);
  return i;
}

std::vector<std::string> order(const std::vector<EffectInfo>& list) {
  std::vector<const EffectInfo*> infos;
  for (const EffectInfo& i : list) infos.push_back(&i);
  std::vector<std::string> names;
  for (size_t i : orderEffects(infos)) names.push_back(list[i].name);
  return names;
}

TEST(EffectContract, AReaderRunsAfterTheProducerWhateverTheGivenOrder) {
  const EffectInfo ao = effect("ao", {"depth"}, {"ao"}), uses = effect("uses", {"ao"}, {"x"}),
                   other = effect("other", {"depth"}, {"y"});
  EXPECT_EQ(order({uses, ao, other}), (std::vector<std::string>{"ao", "uses", "other"}));
  EXPECT_EQ(order({other, uses, ao}), (std::vector<std::string>{"other", "ao", "uses"}));
  // A chain of three, given backwards.
  const EffectInfo c = effect("c", {"x"}, {"z"});
  EXPECT_EQ(order({c, uses, ao}), (std::vector<std::string>{"ao", "uses", "c"}));
}

TEST(EffectContract, InPlaceModifiersKeepTheGivenOrder) {
  // Both read and write "lit" (post effects): neither orders the other.
  const EffectInfo a = effect("vignette", {"lit"}, {"lit"}), b = effect("grade", {"lit"}, {"lit"});
  EXPECT_EQ(order({a, b}), (std::vector<std::string>{"vignette", "grade"}));
  EXPECT_EQ(order({b, a}), (std::vector<std::string>{"grade", "vignette"}));
}

TEST(EffectContract, ACycleNamesTheEffectsInIt) {
  const EffectInfo a = effect("a", {"y"}, {"x"}), b = effect("b", {"x"}, {"y"}),
                   free = effect("free", {}, {"z"});
  test::expectError([&] { order({free, a, b}); }, ErrorKind::Usage, {"effects a, b", "cycle"});
}

TEST(EffectContract, LookUpsAndPublicationsMustBeDeclared) {
  const EffectInfo ssao = effect("ssao", {"depth", "gbuffer"}, {"ao"});
  const auto none = [](const std::string&) { return false; };
  EXPECT_NO_THROW(checkEffectResources(ssao, {"depth", "gbuffer"}, {"ao"}, none));
  EXPECT_NO_THROW(checkEffectResources(ssao, {}, {}, none)) << "adding nothing is allowed";
  test::expectError(
      [&] {
        checkEffectResources(ssao, {"depth", "normal"}, {"ao"}, none);
      },
      ErrorKind::Usage, {"effect 'ssao' reads 'normal'", "does not declare"});
  test::expectError(
      [&] {
        checkEffectResources(ssao, {"depth"}, {"ao", "bent"}, none);
      },
      ErrorKind::Usage, {"effect 'ssao' publishes 'bent'"});
  const EffectInfo two = effect("two", {}, {"ao", "contact_shadow"});
  test::expectError([&] { checkEffectResources(two, {}, {"contact_shadow"}, none); },
                    ErrorKind::Usage, {"declares it writes 'ao' but published nothing"});
  // An optional input may stay unpublished (its neutral fallback stands in).
  EXPECT_NO_THROW(checkEffectResources(two, {}, {"ao"},
                                       [](const std::string& n) { return n == "contact_shadow"; }));
}

}  // namespace
}  // namespace gi

namespace gi {
namespace {

TEST(EffectContract, AnOutputReplacedWithoutBeingReadNamesBothEffects) {
  const std::vector<Masking> none;
  // b publishes "ao" after a did, without looking it up: a's would reach nothing.
  test::expectError(
      [&] {
        checkComposition({{"a", {"depth"}, {"ao"}}, {"b", {"depth"}, {"ao"}}}, none);
      },
      ErrorKind::Usage, {"effects 'a' and 'b' both write 'ao'", "'b' does not read it"});
  // A chain (each reads "lit" and writes it anew) composes.
  EXPECT_NO_THROW(checkComposition(
      {{"a", {"depth"}, {"x"}}, {"f1", {"lit"}, {"lit"}}, {"f2", {"lit"}, {"lit"}}}, none));
  // One effect may publish a name twice in a build; different names never clash.
  EXPECT_NO_THROW(checkComposition({{"a", {}, {"ao", "x"}}, {"b", {}, {"indirect"}}}, none));
}

TEST(EffectContract, AnOutputMaskedByAnotherEffectsNeedsItsReader) {
  const std::vector<Masking> masks = {
      {"ambient", "replaces the environment term", "ao", "multiplies the environment term"}};
  // Whatever the order, the masked effect is named with the one that masks it.
  for (bool aoFirst : {true, false}) {
    std::vector<EffectPublications> list = {{"occ", {"depth"}, {"ao"}},
                                            {"gi", {"depth"}, {"ambient", "indirect"}}};
    if (!aoFirst) std::swap(list[0], list[1]);
    test::expectError([&] { checkComposition(list, masks); }, ErrorKind::Usage,
                      {"effect 'gi' writes 'ambient' (replaces the environment term)",
                       "'occ''s 'ao' (multiplies the environment term)"});
  }
  // An effect that reads "ao" composes the two itself; one effect may publish both.
  EXPECT_NO_THROW(
      checkComposition({{"occ", {"depth"}, {"ao"}}, {"gi", {"depth", "ao"}, {"ambient"}}}, masks));
  EXPECT_NO_THROW(checkComposition({{"both", {"depth"}, {"ao", "ambient"}}}, masks));
  EXPECT_NO_THROW(checkComposition({{"gi", {"depth"}, {"ambient"}}}, masks));
}

}  // namespace
}  // namespace gi
