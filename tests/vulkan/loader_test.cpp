// What happens when Vulkan is missing or broken: no loader, a library that is no loader, no
// driver, no validation layer; VK_CHECK's messages; and `phyxel info`.
#include <gtest/gtest.h>

#include <cstdlib>
#include <optional>
#include <string>

#include "app/commands.h"
#include "compute/instance.h"
#include "tests/support/scoped_env.h"
#include "tests/support/support.h"
#include "vulkan_test.h"

namespace phyxel::gpu {
namespace {

using phyxel::test::error_of;
using phyxel::test::ScopedEnv;

TEST(Loader, MissingLoaderIsAClearError) {
  const std::string message = error_of<VulkanError>([] {
    ContextOptions options;
    options.loader_path = "/nonexistent/libvulkan.so.1";
    Context unused(options);
  });
  EXPECT_NE(message.find("no Vulkan loader (/nonexistent/libvulkan.so.1) found"), std::string::npos)
      << message;
  EXPECT_NE(message.find("install libvulkan1 and a driver such as mesa-vulkan-drivers"),
            std::string::npos)
      << message;
  EXPECT_NE(message.find("--device cpu"), std::string::npos) << message;
}

TEST(Loader, EnvironmentOverridesTheDefaultPath) {
  EXPECT_EQ(vulkan_loader_path(), std::getenv("PHYXEL_VULKAN_LOADER") != nullptr
                                      ? std::string(std::getenv("PHYXEL_VULKAN_LOADER"))
                                      : std::string("libvulkan.so.1"));
  const ScopedEnv env("PHYXEL_VULKAN_LOADER", "/nonexistent/loader.so");
  EXPECT_EQ(vulkan_loader_path(), "/nonexistent/loader.so");
  EXPECT_EQ(vulkan_loader_path("/explicit.so"), "/explicit.so");
  EXPECT_NE(error_of<VulkanError>([] {
              Instance unused;
            }).find("no Vulkan loader (/nonexistent/loader.so)"),
            std::string::npos);
}

TEST(Loader, LibraryThatIsNoLoaderIsRejected) {
  InstanceOptions options;
  options.loader_path = "libm.so.6";
  const std::string message = error_of<VulkanError>([&] { Instance unused(options); });
  EXPECT_NE(message.find("is not a Vulkan loader"), std::string::npos) << message;
}

TEST(Loader, NoDriverIsOneLineSuggestingCpu) {
  test_context_options();  // settles the environment first; the driver list is then replaced
  const ScopedEnv files("VK_DRIVER_FILES", "/nonexistent/icd.json");
  const ScopedEnv names("VK_ICD_FILENAMES", "/nonexistent/icd.json");
  const std::string message = error_of<VulkanError>([] { Context unused(ContextOptions{}); });
  EXPECT_NE(message.find("no Vulkan device found"), std::string::npos) << message;
  EXPECT_NE(message.find("--device cpu"), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

TEST(Loader, MissingValidationLayerNamesThePackage) {
  test_context_options();
  const ScopedEnv layers("VK_LAYER_PATH", "/nonexistent");
  InstanceOptions options;
  options.validation = true;
  const std::string message = error_of<VulkanError>([&] { Instance unused(options); });
  EXPECT_NE(message.find("VK_LAYER_KHRONOS_validation"), std::string::npos) << message;
  EXPECT_NE(message.find("vulkan-validationlayers"), std::string::npos) << message;
}

TEST(VkCheck, NamesTheCallTheLineAndTheResult) {
  int line = 0;
  const std::string message = error_of<VulkanError>([&] {
    line = __LINE__ + 1;
    VK_CHECK(VkResult(VK_ERROR_INITIALIZATION_FAILED));
  });
  EXPECT_NE(message.find("VkResult(VK_ERROR_INITIALIZATION_FAILED)"), std::string::npos);
  EXPECT_NE(message.find("loader_test.cpp:" + std::to_string(line)), std::string::npos) << message;
  EXPECT_NE(message.find("with VK_ERROR_INITIALIZATION_FAILED"), std::string::npos) << message;
}

TEST(VkCheck, DeviceLostAndOutOfMemorySuggestASmallerSceneOrCpu) {
  for (const VkResult result : {VK_ERROR_DEVICE_LOST, VK_ERROR_OUT_OF_DEVICE_MEMORY}) {
    try {
      VK_CHECK(result);
      FAIL() << "VK_CHECK did not throw";
    } catch (const VulkanError& e) {
      const std::string message = e.what();
      EXPECT_EQ(e.result(), result);
      EXPECT_NE(message.find(vk_result_name(result)), std::string::npos) << message;
      EXPECT_NE(message.find("smaller scene"), std::string::npos) << message;
      EXPECT_NE(message.find("--device cpu"), std::string::npos) << message;
    }
  }
}

TEST(VkCheck, EveryNonSuccessThrows) {
  EXPECT_NO_THROW(VK_CHECK(VK_SUCCESS));
  EXPECT_THROW(VK_CHECK(VK_TIMEOUT), VulkanError);
  EXPECT_THROW(VK_CHECK(VK_INCOMPLETE), VulkanError);
  EXPECT_EQ(vk_result_name(VK_ERROR_OUT_OF_POOL_MEMORY), "VK_ERROR_OUT_OF_POOL_MEMORY");
  EXPECT_EQ(vk_result_name(static_cast<VkResult>(-123456)), "VkResult(-123456)");
}

TEST(Info, ListsTheDevices) {
  test_context_options();
  testing::internal::CaptureStdout();
  const int rc = app::info_command({"--validate"});
  const std::string out = testing::internal::GetCapturedStdout();
  EXPECT_EQ(rc, 0) << out;
  for (const char* field : {"device 0:", "type", "driver", "Vulkan API", "device-local memory",
                            "max workgroup size", "max storage buffer", "subgroup size",
                            "timestamps", "float64", "selects device", "validation: 0 errors"}) {
    EXPECT_NE(out.find(field), std::string::npos) << field << " missing from:\n" << out;
  }
}

TEST(Info, WithoutLoaderThrowsTheClearMessage) {
  const ScopedEnv env("PHYXEL_VULKAN_LOADER", "/nonexistent/libvulkan.so.1");
  const std::string message = error_of<VulkanError>([] { app::info_command({}); });
  EXPECT_NE(message.find("no Vulkan loader"), std::string::npos) << message;
}

TEST(Info, RejectsUnknownArguments) {
  testing::internal::CaptureStderr();
  EXPECT_EQ(app::info_command({"--bogus"}), 2);
  EXPECT_NE(testing::internal::GetCapturedStderr().find("--bogus"), std::string::npos);
}

}  // namespace
}  // namespace phyxel::gpu
