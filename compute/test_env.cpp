#include "compute/test_env.h"

#include <cstdlib>
#include <filesystem>
#include <system_error>

#include "compute/env.h"

namespace phyxel::gpu {

std::string find_lavapipe_icd() {
  namespace fs = std::filesystem;
  for (const char* dir :
       {"/usr/share/vulkan/icd.d", "/usr/local/share/vulkan/icd.d", "/etc/vulkan/icd.d"}) {
    std::error_code error;
    for (fs::directory_iterator it(dir, error), end; !error && it != end; it.increment(error)) {
      const std::string name = it->path().filename().string();
      if (name.rfind("lvp_icd", 0) == 0 && it->path().extension() == ".json") {
        return it->path().string();
      }
    }
  }
  return {};
}

ContextOptions test_context_options() {
  ContextOptions options;
  const std::string spec = env_text("PHYXEL_TEST_DEVICE");
  if (spec.empty() || spec == "lavapipe") {
    const std::string icd = find_lavapipe_icd();
    if (icd.empty()) {
      throw VulkanError(
          "the tests run on lavapipe, but its ICD (lvp_icd.*.json) is not installed: install "
          "mesa-vulkan-drivers, or set PHYXEL_TEST_DEVICE=gpu to test the real device",
          VK_ERROR_INCOMPATIBLE_DRIVER);
    }
    setenv("VK_DRIVER_FILES", icd.c_str(), 1);
    setenv("VK_ICD_FILENAMES", icd.c_str(), 1);  // the name loaders before 1.3.207 read
    options.device = "gpu";
  } else {
    options.device = spec;
  }
  options.validation = env_switch("PHYXEL_TEST_VALIDATION");
  return options;
}

}  // namespace phyxel::gpu
