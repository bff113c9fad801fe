// `phyxel bench --accuracy` (bench_accuracy.cpp).
#pragma once

#include <functional>
#include <string>

#include "app/commands.h"
#include "engine/run/validation.h"

namespace phyxel::app {

// Makes the solver factory for a device name ("cpu", "gpu", ...) and a CPU thread count.
using DeviceSolverFactory = std::function<SolverFactory(const std::string& device, int threads)>;

int bench_accuracy(const Args& args, const DeviceSolverFactory& device_factory);

}  // namespace phyxel::app
