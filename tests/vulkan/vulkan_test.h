// Fixture for tests that need a Vulkan context: lavapipe with validation (see
// compute/test_env.h). Every test fails if the validation layer reported an error or a warning,
// including what it said while the context was destroyed.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "compute/test_env.h"

namespace phyxel::gpu {

inline void expect_no_validation_messages(const std::shared_ptr<const ValidationLog>& log) {
  if (log == nullptr) return;  // PHYXEL_TEST_VALIDATION=0
  EXPECT_EQ(log->error_count(), 0u) << log->summary();
  EXPECT_EQ(log->warning_count(), 0u) << log->summary();
}

class VulkanTest : public ::testing::Test {
 protected:
  void SetUp() override { ctx_ = &make_context(); }

  void TearDown() override {
    for (std::unique_ptr<Context>& ctx : contexts_) {
      auto log = ctx->validation_log();
      ctx.reset();
      expect_no_validation_messages(log);
    }
  }

  // Another context (kept until the end of the test, then checked like the first).
  Context& make_context(const ContextOptions& options = test_context_options()) {
    contexts_.push_back(std::make_unique<Context>(options));
    return *contexts_.back();
  }

  Context& ctx() { return *ctx_; }

 private:
  std::vector<std::unique_ptr<Context>> contexts_;
  Context* ctx_ = nullptr;
};

}  // namespace phyxel::gpu
