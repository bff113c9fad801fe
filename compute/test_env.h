// Context options for tests of GPU code (any test area): lavapipe with validation, unless the
// environment says otherwise.
//
//   PHYXEL_TEST_DEVICE      unset or "lavapipe": point the Vulkan loader at Mesa's lavapipe
//                           ICD (setting VK_DRIVER_FILES and VK_ICD_FILENAMES in this
//                           process) and use it; anything else: a --device spec ("gpu",
//                           "gpu:1", "nvidia") on the drivers the loader finds by itself
//   PHYXEL_TEST_VALIDATION  "0" turns validation off (it is on by default)
#pragma once

#include <string>

#include "compute/context.h"

namespace phyxel::gpu {

// Mesa's lavapipe ICD manifest (lvp_icd.<arch>.json) in the usual places; "" when absent.
std::string find_lavapipe_icd();

// Sets the process environment as described above (before any instance exists) and returns
// the options to create the test's Context with. Throws VulkanError when lavapipe is wanted
// but not installed.
ContextOptions test_context_options();

}  // namespace phyxel::gpu
