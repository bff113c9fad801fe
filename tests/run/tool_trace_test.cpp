// tools.csv rows (engine/run/tool_trace.h): the writer formats numbers with std::to_chars;
// every row must read exactly as printf's "%.9g" / "%.6g" row the format documents, for
// ordinary, tiny, huge, negative, zero, negative-zero and non-finite values.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "engine/run/tool_trace.h"
#include "tests/physics/physics_fixtures.h"

namespace phyxel {
namespace {

std::string printf_row(int64_t step, double t, const std::string& name, const ToolStepRecord& r) {
  char row[1024];
  const CutFeedback& c = r.cut;
  std::snprintf(row, sizeof row,
                "%lld,%.9g,%s,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%u,%.6g,%.6g,%.6g,%.6g,"
                "%.6g,%.6g,%.6g,%.6g\n",
                static_cast<long long>(step), t, name.c_str(), r.pose.position.x(),
                r.pose.position.y(), r.pose.position.z(), r.pose.axis.x(), r.pose.axis.y(),
                r.pose.axis.z(), r.force.x(), r.force.y(), r.force.z(), r.contacts, c.cut_force,
                c.theta, c.in_plane, c.normal, c.depth, c.friction.x(), c.friction.y(),
                c.friction.z());
  return row;
}

TEST(ToolTrace, RowsReadAsThePrintfFormat) {
  const std::filesystem::path file = test::test_output_dir("tool_trace") / "tools.csv";
  ToolDesc probe;
  probe.name = "probe";
  ToolDesc scalpel;
  scalpel.name = "scalpel";
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> mantissa(-1, 1);
  std::uniform_int_distribution<int> exponent(-320, 308);
  const double special[] = {0.0,
                            -0.0,
                            1.0,
                            -2.5e-7,
                            123456789.0,
                            1e300,
                            4.9e-324,
                            std::numeric_limits<double>::infinity(),
                            -std::numeric_limits<double>::infinity(),
                            std::numeric_limits<double>::quiet_NaN()};
  size_t next_special = 0;
  auto value = [&]() {
    if (rng() % 4 == 0) return special[next_special++ % std::size(special)];
    return mantissa(rng) * std::pow(10.0, exponent(rng) / 2);
  };
  std::string expected;
  {
    ToolTraceWriter trace(file, {probe, scalpel});
    for (int64_t step = 0; step < 300; ++step) {
      std::vector<ToolStepRecord> records(2);
      for (ToolStepRecord& r : records) {
        r.pose.position = Vec3(value(), value(), value());
        r.pose.axis = Vec3(value(), value(), value());
        r.force = Vec3(value(), value(), value());
        r.contacts = static_cast<uint32_t>(rng() % 100000);
        r.cut.cut_force = value();
        r.cut.theta = value();
        r.cut.in_plane = value();
        r.cut.normal = value();
        r.cut.depth = value();
        r.cut.friction = Vec3(value(), value(), value());
      }
      const double t = step * 1.7e-4;
      trace.write(step, t, records);
      expected += printf_row(step, t, "probe", records[0]);
      expected += printf_row(step, t, "scalpel", records[1]);
    }
    trace.close();
  }
  std::ifstream in(file);
  std::string header;
  std::getline(in, header);
  std::stringstream rest;
  rest << in.rdbuf();
  EXPECT_EQ(rest.str(), expected);
}

}  // namespace
}  // namespace phyxel
