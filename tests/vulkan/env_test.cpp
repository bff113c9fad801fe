// The PHYXEL_* environment parsing (compute/env.h): what a switch and a number take, what
// unset means, and the one-line error naming the variable and what it takes.
#include <gtest/gtest.h>

#include <cstdlib>
#include <optional>
#include <string>
#include <utility>

#include "compute/env.h"
#include "tests/support/scoped_env.h"
#include "tests/support/support.h"

namespace phyxel::gpu {
namespace {

using phyxel::test::error_of;
using phyxel::test::ScopedEnv;

constexpr const char* kName = "PHYXEL_ENV_TEST_VALUE";

std::optional<int64_t> seconds() {
  return env_number(kName, 1, 86400, "seconds", "the default (120)");
}

TEST(Env, ASwitchIsOnUnlessZero) {
  ::unsetenv(kName);
  EXPECT_TRUE(env_switch(kName));
  for (const char* on : {"", "1"}) {
    const ScopedEnv env(kName, on);
    EXPECT_TRUE(env_switch(kName)) << "'" << on << "'";
  }
  const ScopedEnv env(kName, "0");
  EXPECT_FALSE(env_switch(kName));
}

TEST(Env, ASwitchRefusesAnythingElseNamingTheVariable) {
  for (const char* bad : {"off", "false", "2", "00", " 0", "yes"}) {
    const ScopedEnv env(kName, bad);
    EXPECT_EQ(error_of<EnvError>([] { env_switch(kName); }),
              std::string(kName) + "='" + bad +
                  "' is neither 0 (off) nor 1 (on); unset it for the default (on)");
  }
}

TEST(Env, ANumberIsReadWithinItsRange) {
  ::unsetenv(kName);
  EXPECT_FALSE(seconds().has_value());
  {
    const ScopedEnv env(kName, "");
    EXPECT_FALSE(seconds().has_value());
  }
  for (const auto& [text, value] :
       {std::pair{"1", 1}, std::pair{"7", 7}, std::pair{"86400", 86400}}) {
    const ScopedEnv env(kName, text);
    EXPECT_EQ(seconds(), value) << text;
  }
}

TEST(Env, ANumberRefusesAnythingElseNamingTheVariable) {
  for (const char* bad : {"0", "-5", "2m", "86401", "1.5", "x", "99999999999999999999"}) {
    const ScopedEnv env(kName, bad);
    const std::string message = error_of<EnvError>([] { seconds(); });
    EXPECT_EQ(message, std::string(kName) + "='" + bad +
                           "' is not a whole number of seconds from 1 to 86400; unset it for "
                           "the default (120)");
    EXPECT_EQ(message.find('\n'), std::string::npos);
  }
}

TEST(Env, TextIsEmptyWhenUnset) {
  ::unsetenv(kName);
  EXPECT_EQ(env_text(kName), "");
  const ScopedEnv env(kName, "/opt/libvulkan.so.1");
  EXPECT_EQ(env_text(kName), "/opt/libvulkan.so.1");
}

}  // namespace
}  // namespace phyxel::gpu
