// Deeply nested documents: a nesting limit refuses them at once with a one-line message whose
// path is shortened, and long paths in any message are capped.
#include <gtest/gtest.h>

#include <string>

#include "engine/scene/json_reader.h"
#include "tests/scene/scene_error_helpers.h"

namespace phyxel::scene_test {
namespace {

TEST(SceneNesting, TwoHundredThousandBracketsAreRefusedAtLevel65OnOneShortLine) {
  for (const bool closed : {false, true}) {
    const std::string text =
        std::string(200000, '[') + (closed ? std::string(200000, ']') : std::string());
    // Refused at level 65 (the message says so), not after reading all 200 000 levels.
    const std::string msg = error_text(text);
    EXPECT_LT(msg.size(), 300u) << msg.substr(0, 1000);
    EXPECT_EQ(msg.find('\n'), std::string::npos);
    EXPECT_EQ(msg.rfind(std::string(kFile) + ": [0][0][0]...(58 more levels)...[0][0][0]: ", 0), 0u)
        << msg;
    EXPECT_NE(msg.find("more than 64 levels deep"), std::string::npos) << msg;
    EXPECT_NE(msg.find("allowed at most 64 levels"), std::string::npos) << msg;
  }
}

TEST(SceneNesting, DeepObjectsAreRefusedToo) {
  std::string text;
  for (int i = 0; i < 100000; ++i) text += "{\"a\":";
  const std::string msg = error_text(text + "1" + std::string(100000, '}'));
  EXPECT_LT(msg.size(), 300u) << msg.substr(0, 1000);
  EXPECT_EQ(msg.rfind(std::string(kFile) + ": a.a.a...(58 more levels)....a.a.a: ", 0), 0u) << msg;
}

TEST(SceneNesting, SixtyFourLevelsAreAllowedAndSixtyFiveAreNot) {
  // The top-level object and 63 arrays: 64 levels, parsed; only the unknown key is reported.
  json j = demo();
  json deep = 1;
  for (int i = 0; i < 63; ++i) deep = json::array({deep});
  j["extra"] = deep;
  expect_error(error_text(j.dump()), "extra", {"unknown key \"extra\""});
  j["extra"] = json::array({deep});
  expect_error(error_text(j.dump()), "extra[0][0]...(58 more levels)...[0][0][0]",
               {"more than 64 levels deep"});
}

TEST(SceneNesting, LongPathsAreShortenedInMessages) {
  using json_reader::shorten_path;
  EXPECT_EQ(shorten_path("objects[0].material.poisson"), "objects[0].material.poisson");
  EXPECT_EQ(shorten_path("a.b.c.d.e.f.g"), "a.b.c.d.e.f.g");
  EXPECT_EQ(shorten_path("a.b.c.d.e.f.g.h"), "a.b.c...(2 more levels)....f.g.h");
  const std::string key(1000, 'k');
  EXPECT_EQ(shorten_path("objects[0]." + key), "objects[0]." + std::string(39, 'k') + "...");
  // A misspelt key of a megabyte is named, but shortly.
  json j = demo();
  object0(j)[std::string(1 << 20, 'x')] = 1;
  const std::string msg = error_text(j.dump());
  EXPECT_LT(msg.size(), 600u) << msg.substr(0, 1000);
  EXPECT_EQ(msg.rfind(std::string(kFile) + ": objects[0]." + std::string(39, 'x') + "...: ", 0), 0u)
      << msg.substr(0, 300);
}

}  // namespace
}  // namespace phyxel::scene_test
