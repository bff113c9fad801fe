// Tool-tissue contact (engine/solver/contact.h): the projection of one phyxel to the tool's
// surface with Coulomb friction, in double and float, and the rest-space broad phase against a
// brute-force search.
#include "engine/solver/contact.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <iterator>
#include <limits>
#include <random>
#include <vector>

namespace phyxel {
namespace {

using Vec3f = Eigen::Vector3f;

const ContactTool kSphere{{ToolShape::Type::Sphere, 0.01, 0}, 0, {}, {}, {}};
// A capsule along z from the origin: its side is the cylinder r = 0.01, 0 <= z <= 0.05.
const ContactTool kCapsule{{ToolShape::Type::Capsule, 0.01, 0.05}, 0, {}, {}, {}};

ContactTool with_friction(ContactTool tool, double mu) {
  tool.friction = mu;
  return tool;
}

ToolMotion at_rest(const Vec3& tip) {
  return {{tip, Vec3::UnitZ()}, {tip, Vec3::UnitZ()}};
}

// --- the narrow phase and response ---

TEST(ContactCorrection, DoubleEndsExactlyOnTheSphereWithoutFriction) {
  const ToolMotion motion = at_rest(Vec3(0.1, 0.2, 0.3));
  std::mt19937 rng(1);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> depth(0.0001, 0.0099);
  for (int i = 0; i < 200; ++i) {
    const Vec3 dir = Vec3(g(rng), g(rng), g(rng)).normalized();
    const Vec3 x_new = motion.to.position + (0.01 - depth(rng)) * dir;
    const Vec3 x_prev = x_new + 0.001 * Vec3(g(rng), g(rng), g(rng));  // any earlier position
    Vec3 dx = Vec3::Constant(7);
    Vec3 dv;
    ASSERT_TRUE(
        contact_correction<double>(kSphere, motion, 1e-3, x_prev, x_new, Vec3::Zero(), dx, dv));
    EXPECT_LT(std::abs(tool_distance(kSphere.shape, motion.to, x_new + dx).distance), 1e-12);
    EXPECT_NEAR(dx.normalized().dot(dir), 1, 1e-12);  // straight out along the normal
  }
}

TEST(ContactCorrection, FloatEndsOnTheSphereWithinFloatRounding) {
  const ToolMotion motion = at_rest(Vec3(0.1, 0.2, 0.3));
  std::mt19937 rng(2);
  std::normal_distribution<double> g;
  for (int i = 0; i < 200; ++i) {
    const Vec3 dir = Vec3(g(rng), g(rng), g(rng)).normalized();
    const Vec3f x_new = (motion.to.position + 0.006 * dir).cast<float>();
    Vec3f dx = Vec3f::Constant(7);
    Vec3f dvf;
    ASSERT_TRUE(
        contact_correction<float>(kSphere, motion, 1e-3f, x_new, x_new, Vec3f::Zero(), dx, dvf));
    const Vec3f end = x_new + dx;
    // Float positions near 0.3 m are spaced 3e-8 m apart.
    EXPECT_LT(std::abs(tool_distance(kSphere.shape, motion.to, end.cast<double>()).distance), 2e-7);
  }
}

TEST(ContactCorrection, NoCorrectionOutside) {
  const ToolMotion motion = at_rest(Vec3(0.1, 0.2, 0.3));
  for (const ContactTool& tool : {kSphere, with_friction(kCapsule, 0.5)}) {
    for (const Vec3& x : {Vec3(0.1, 0.2, 0.3 - 0.0101), Vec3(0.2, 0.2, 0.3), Vec3(0.1, 0.2, 0.37),
                          Vec3(0.1, 0.211, 0.32)}) {
      Vec3 dx = Vec3::Constant(7);
      Vec3 dv;
      EXPECT_FALSE(contact_correction<double>(tool, motion, 1e-3, x, x, Vec3::Zero(), dx, dv))
          << x.transpose();
      EXPECT_EQ(dx, Vec3::Constant(7));
      Vec3f dxf = Vec3f::Constant(7);
      Vec3f dvf;
      EXPECT_FALSE(contact_correction<float>(tool, motion, 1e-3f, Vec3f(x.cast<float>()),
                                             Vec3f(x.cast<float>()), Vec3f::Zero(), dxf, dvf));
      EXPECT_EQ(dxf, Vec3f::Constant(7));
    }
  }
}

// Friction on the capsule's flat direction (along its axis): the phyxel comes from just outside
// the side at z = 0.02, is pushed 1 mm into it and slips `slip` along z.
struct SideCase {
  Vec3 x_prev = Vec3(0.0105, 0, 0.02);
  Vec3 x_new;
  explicit SideCase(double slip) : x_new(0.009, 0, 0.02 + slip) {}
};

TEST(ContactCorrection, LargeFrictionSticks) {
  const SideCase c(0.0002);
  Vec3 dx;
  Vec3 dv;
  ASSERT_TRUE(contact_correction<double>(with_friction(kCapsule, 1.0), at_rest(Vec3::Zero()), 1e-3,
                                         c.x_prev, c.x_new, Vec3::Zero(), dx, dv));
  const Vec3 end = c.x_new + dx;
  EXPECT_NEAR((end - Vec3(0.01, 0, 0.02)).norm(), 0, 1e-15);  // on the side, no slip at all
}

TEST(ContactCorrection, SlidingLosesMuTimesTheNormalCorrection) {
  for (double mu : {0.0, 0.05, 0.1, 0.19}) {
    const SideCase c(0.0002);
    Vec3 dx;
    Vec3 dv;
    ASSERT_TRUE(contact_correction<double>(with_friction(kCapsule, mu), at_rest(Vec3::Zero()), 1e-3,
                                           c.x_prev, c.x_new, Vec3::Zero(), dx, dv));
    const Vec3 end = c.x_new + dx;
    const double dn = 0.001;  // the phyxel was 1 mm inside
    EXPECT_NEAR(end.x(), 0.01, 1e-15) << mu;
    EXPECT_NEAR(end.y(), 0, 1e-15) << mu;
    EXPECT_NEAR(end.z() - c.x_prev.z(), 0.0002 - mu * dn, 1e-15) << mu;
  }
}

TEST(ContactCorrection, JustBelowTheLimitSticksJustAboveSlidesByTheExcess) {
  // |slip| = 0.8 mu |dn| sticks; |slip| = 1.25 mu |dn| slides by the excess over mu |dn|.
  const SideCase at(0.0002), above(0.00025);
  Vec3 dx;
  Vec3 dv;
  ASSERT_TRUE(contact_correction<double>(with_friction(kCapsule, 0.25), at_rest(Vec3::Zero()), 1e-3,
                                         at.x_prev, at.x_new, Vec3::Zero(), dx, dv));
  EXPECT_NEAR((at.x_new + dx).z(), 0.02, 1e-15);
  ASSERT_TRUE(contact_correction<double>(with_friction(kCapsule, 0.2), at_rest(Vec3::Zero()), 1e-3,
                                         above.x_prev, above.x_new, Vec3::Zero(), dx, dv));
  EXPECT_NEAR((above.x_new + dx).z(), 0.02 + 0.00005, 1e-15);
}

TEST(ContactCorrection, FrictionIsRelativeToTheMovingTool) {
  // The tool moves 1 mm along its axis; a phyxel at rest 1 mm inside its side is dragged along
  // when friction sticks, and only pushed out without friction.
  const ToolMotion motion{{Vec3::Zero(), Vec3::UnitZ()}, {Vec3(0, 0, 0.001), Vec3::UnitZ()}};
  const Vec3 x(0.009, 0, 0.02);
  Vec3 dx;
  Vec3 dv;
  ASSERT_TRUE(contact_correction<double>(with_friction(kCapsule, 2.0), motion, 1e-3, x, x,
                                         Vec3::Zero(), dx, dv));
  EXPECT_NEAR((x + dx - Vec3(0.01, 0, 0.021)).norm(), 0, 1e-15);
  ASSERT_TRUE(contact_correction<double>(kCapsule, motion, 1e-3, x, x, Vec3::Zero(), dx, dv));
  EXPECT_NEAR((x + dx - Vec3(0.01, 0, 0.02)).norm(), 0, 1e-15);
  ASSERT_TRUE(contact_correction<double>(with_friction(kCapsule, 0.5), motion, 1e-3, x, x,
                                         Vec3::Zero(), dx, dv));
  EXPECT_NEAR((x + dx - Vec3(0.01, 0, 0.0205)).norm(), 0, 1e-15);  // slides: 0.5 of 1 mm
}

TEST(ContactCorrection, FloatFrictionMatchesDouble) {
  for (double mu : {0.0, 0.1, 1.0}) {
    const SideCase c(0.0002);
    Vec3 dx;
    Vec3 dv;
    Vec3f dxf;
    Vec3f dvf;
    ASSERT_TRUE(contact_correction<double>(with_friction(kCapsule, mu), at_rest(Vec3::Zero()), 1e-3,
                                           c.x_prev, c.x_new, Vec3::Zero(), dx, dv));
    ASSERT_TRUE(contact_correction<float>(with_friction(kCapsule, mu), at_rest(Vec3::Zero()), 1e-3f,
                                          Vec3f(c.x_prev.cast<float>()),
                                          Vec3f(c.x_new.cast<float>()), Vec3f::Zero(), dxf, dvf));
    EXPECT_LT((dxf.cast<double>() - dx).norm(), 1e-8) << mu;
  }
}

// The velocity response: relative to the tool surface, the normal velocity into the tool is
// removed, a separating one kept, and the tangential one reduced within mu times the normal
// change.
TEST(ContactCorrection, VelocityIntoTheToolIsRemovedSeparatingKept) {
  const SideCase c(0);
  Vec3 dx, dv;
  // Moving into the side (-x) at 0.5 m/s and along z at 0.1 m/s, no friction.
  ASSERT_TRUE(contact_correction<double>(kCapsule, at_rest(Vec3::Zero()), 1e-3, c.x_prev, c.x_new,
                                         Vec3(-0.5, 0, 0.1), dx, dv));
  EXPECT_NEAR((dv - Vec3(0.5, 0, 0)).norm(), 0, 1e-15);
  // Already moving out (+x): no velocity change, the position is still corrected.
  ASSERT_TRUE(contact_correction<double>(kCapsule, at_rest(Vec3::Zero()), 1e-3, c.x_prev, c.x_new,
                                         Vec3(0.3, 0, 0.1), dx, dv));
  EXPECT_EQ(dv, Vec3::Zero());
  EXPECT_NEAR(dx.x(), 0.001, 1e-15);
}

TEST(ContactCorrection, TangentialVelocityObeysCoulomb) {
  const SideCase c(0);
  Vec3 dx, dv;
  // Normal change 0.5 m/s; tangential 0.1 m/s: mu = 0.1 takes 0.05 of it (sliding), mu = 1
  // all of it (sticking).
  ASSERT_TRUE(contact_correction<double>(with_friction(kCapsule, 0.1), at_rest(Vec3::Zero()), 1e-3,
                                         c.x_prev, c.x_new, Vec3(-0.5, 0, 0.1), dx, dv));
  EXPECT_NEAR((dv - Vec3(0.5, 0, -0.05)).norm(), 0, 1e-15);
  ASSERT_TRUE(contact_correction<double>(with_friction(kCapsule, 1.0), at_rest(Vec3::Zero()), 1e-3,
                                         c.x_prev, c.x_new, Vec3(-0.5, 0, 0.1), dx, dv));
  EXPECT_NEAR((dv - Vec3(0.5, 0, -0.1)).norm(), 0, 1e-15);
}

TEST(ContactCorrection, VelocityIsRelativeToTheMovingTool) {
  // The tool moves 1 mm along +z in a substep of 1 ms (1 m/s); a phyxel inside its side moving
  // into it at 0.2 m/s with no z velocity: sticking friction gives it the tool's 1 m/s along z.
  const ToolMotion motion{{Vec3::Zero(), Vec3::UnitZ()}, {Vec3(0, 0, 0.001), Vec3::UnitZ()}};
  const Vec3 x(0.009, 0, 0.02);
  Vec3 dx, dv;
  ASSERT_TRUE(contact_correction<double>(with_friction(kCapsule, 10.0), motion, 1e-3, x, x,
                                         Vec3(-0.2, 0, 0), dx, dv));
  EXPECT_NEAR((dv - Vec3(0.2, 0, 1.0)).norm(), 0, 1e-12);
}

// --- the broad phase ---

// A hand-made set: `n` phyxels at random rest positions in a box, about 10% fixed and 5%
// removed, in two objects of support radius 0.004 and 0.006 m (the grid's cell is the larger).
PhyxelSet random_set(size_t n, std::mt19937& rng) {
  std::uniform_real_distribution<double> x(-0.05, 0.05), y(0, 0.03), z(0.1, 0.2), u(0, 1);
  PhyxelSet set;
  for (size_t i = 0; i < n; ++i) {
    set.rest.emplace_back(x(rng), y(rng), z(rng));
    const double r = u(rng);
    uint32_t flags = r < 0.1 ? kFixed : r < 0.15 ? kRemoved : 0u;
    if (u(rng) < 0.3) flags |= kSurface;
    set.flags.push_back(flags);
  }
  ObjectRange a, b;
  a.first = 0, a.count = uint32_t(n / 2), a.support_radius = 0.004;
  b.first = a.count, b.count = uint32_t(n - a.count), b.support_radius = 0.006;
  set.objects = {a, b};
  return set;
}

bool inside(const Vec3& p, const Bounds& b, double reach) {
  for (int a = 0; a < 3; ++a) {
    if (!(p[a] >= b.min[a] - reach && p[a] <= b.max[a] + reach)) return false;
  }
  return true;
}

std::vector<uint32_t> every_index(size_t n) {
  std::vector<uint32_t> list(n);
  for (uint32_t i = 0; i < n; ++i) list[i] = i;
  return list;
}

// Every candidate and only those: ascending, none fixed or removed, exactly the phyxels of
// `list` whose current position rest + u is inside the bounds grown by the margin.
void check_candidates(const PhyxelSet& set, const std::vector<Vec3>& u,
                      const std::vector<uint32_t>& list, const Bounds& bounds, double margin) {
  const std::vector<uint32_t> got =
      contact_candidates<double>(list, set.flags, set.rest, u, bounds, margin);
  for (size_t k = 1; k < got.size(); ++k) ASSERT_LT(got[k - 1], got[k]) << "not ascending";
  for (const uint32_t i : list) {
    const bool takes_contact = !(set.flags[i] & (kFixed | kRemoved));
    const bool found = std::binary_search(got.begin(), got.end(), i);
    EXPECT_EQ(found, takes_contact && inside(set.rest[i] + u[i], bounds, margin))
        << "phyxel " << i << " at " << (set.rest[i] + u[i]).transpose();
  }
  for (const uint32_t i : got) EXPECT_TRUE(std::binary_search(list.begin(), list.end(), i)) << i;
}

TEST(BroadPhase, RandomQueriesFindThePhyxelsWhereTheyAreNow) {
  std::mt19937 rng(42);
  const PhyxelSet set = random_set(3000, rng);
  std::uniform_real_distribution<double> cx(-0.07, 0.07), cy(-0.02, 0.05), cz(0.08, 0.22);
  std::uniform_real_distribution<double> half(0, 0.02), margin(0, 0.01), du(-0.02, 0.02);
  std::vector<Vec3> u(set.size());
  for (Vec3& x : u) x = Vec3(du(rng), du(rng), du(rng));
  const std::vector<uint32_t> all = every_index(set.size());
  std::vector<uint32_t> odd;  // a force list that leaves some phyxels out (sleeping objects)
  for (uint32_t i = 1; i < set.size(); i += 2) odd.push_back(i);
  for (int q = 0; q < 300; ++q) {
    const Vec3 c(cx(rng), cy(rng), cz(rng));
    const Vec3 h(half(rng), half(rng), half(rng));
    const Bounds bounds{c - h, c + h};
    const double m = margin(rng);
    check_candidates(set, u, all, bounds, m);
    check_candidates(set, u, odd, bounds, m);
    if (HasFailure()) return;
  }
}

TEST(BroadPhase, ADisplacedPhyxelIsFoundWhereItIsNotWhereItRests) {
  std::mt19937 rng(43);
  PhyxelSet set = random_set(200, rng);
  for (uint32_t& f : set.flags) f &= ~(kFixed | kRemoved);
  std::vector<Vec3> u(set.size(), Vec3::Zero());
  const Bounds tool{Vec3(0.5, 0.5, 0.5), Vec3(0.51, 0.51, 0.51)};  // far from every rest position
  const std::vector<uint32_t> all = every_index(set.size());
  EXPECT_TRUE(contact_candidates<double>(all, set.flags, set.rest, u, tool, 0.001).empty());
  u[17] = Vec3(0.505, 0.505, 0.505) - set.rest[17];  // sagged or dragged into the tool's way
  EXPECT_EQ(contact_candidates<double>(all, set.flags, set.rest, u, tool, 0.001),
            std::vector<uint32_t>{17});
  // And one resting inside the bounds but moved far away is not a candidate.
  set.rest[18] = Vec3(0.505, 0.505, 0.505);
  u[18] = Vec3(-1, 0, 0);
  EXPECT_EQ(contact_candidates<double>(all, set.flags, set.rest, u, tool, 0.001),
            std::vector<uint32_t>{17});
}

TEST(BroadPhase, MarginGrowsTheQueryAndEmptyOrFarBoundsFindNothing) {
  std::mt19937 rng(44);
  const PhyxelSet set = random_set(2000, rng);
  const std::vector<Vec3> u(set.size(), Vec3::Zero());
  const std::vector<uint32_t> all = every_index(set.size());
  const Bounds outside{Vec3(0, 0.04, 0.15), Vec3(0, 0.04, 0.15)};  // a point just outside
  EXPECT_TRUE(contact_candidates<double>(all, set.flags, set.rest, u, outside, 0).empty());
  EXPECT_FALSE(contact_candidates<double>(all, set.flags, set.rest, u, outside, 0.02).empty());
  check_candidates(set, u, all, outside, 0.02);
  EXPECT_TRUE(contact_candidates<double>(all, set.flags, set.rest, u, Bounds{}, 1.0).empty());
  EXPECT_TRUE(
      contact_candidates<double>(all, set.flags, set.rest, u, {Vec3(5, 5, 5), Vec3(6, 6, 6)}, 0.1)
          .empty());
}

TEST(BroadPhase, HugeOrNonFiniteMarginTakesEveryPhyxelThatCanTakeContact) {
  // A diverging simulation gives an enormous, infinite or NaN margin (contact_margin of a huge
  // speed): the candidates are then every phyxel of the list that can take contact.
  std::mt19937 rng(47);
  const PhyxelSet set = random_set(500, rng);
  const std::vector<Vec3> u(set.size(), Vec3::Zero());
  const std::vector<uint32_t> list = every_index(set.size());
  std::vector<uint32_t> all;
  for (uint32_t i = 0; i < set.size(); ++i) {
    if (!(set.flags[i] & (kFixed | kRemoved))) all.push_back(i);
  }
  const Bounds tool{Vec3(0, 0.01, 0.15), Vec3(0.001, 0.011, 0.151)};
  for (double margin : {1e10, 1e30, std::numeric_limits<double>::infinity(),
                        std::numeric_limits<double>::quiet_NaN()}) {
    EXPECT_EQ(contact_candidates<double>(list, set.flags, set.rest, u, tool, margin), all)
        << "margin " << margin;
  }
}

TEST(BroadPhase, SinglePrecisionAgreesWithDouble) {
  std::mt19937 rng(48);
  const PhyxelSet set = random_set(1000, rng);
  std::uniform_real_distribution<double> du(-0.01, 0.01);
  std::vector<Vec3> u(set.size());
  for (Vec3& x : u) x = Vec3(du(rng), du(rng), du(rng));
  std::vector<Eigen::Vector3f> rest_f, u_f;
  for (size_t i = 0; i < set.size(); ++i) {
    rest_f.push_back(set.rest[i].cast<float>());
    u_f.push_back(u[i].cast<float>());
  }
  const std::vector<uint32_t> list = every_index(set.size());
  const Bounds tool{Vec3(-0.01, 0.0, 0.12), Vec3(0.02, 0.02, 0.16)};
  const auto d = contact_candidates<double>(list, set.flags, set.rest, u, tool, 0.003);
  const auto f = contact_candidates<float>(list, set.flags, rest_f, u_f, tool, 0.003);
  ASSERT_FALSE(d.empty());
  // Only phyxels within float rounding of the grown bounds may differ.
  std::vector<uint32_t> differ;
  std::set_symmetric_difference(d.begin(), d.end(), f.begin(), f.end(), std::back_inserter(differ));
  for (const uint32_t i : differ) {
    EXPECT_TRUE(inside(set.rest[i] + u[i], tool, 0.003 + 1e-6) &&
                !inside(set.rest[i] + u[i], tool, 0.003 - 1e-6))
        << i;
  }
}

// --- margin and swept bounds ---

TEST(ContactMargin, TwiceTheTravelAtTheLargestSpeedOfTissueOrToolAndTheSpacing) {
  EXPECT_DOUBLE_EQ(contact_margin(0.002, 0.5, 0.1, 0.004), 2 * 0.004 * 0.5 + 0.002);
  EXPECT_DOUBLE_EQ(contact_margin(0.002, 0.1, 0.5, 0.004), 2 * 0.004 * 0.5 + 0.002);
  EXPECT_DOUBLE_EQ(contact_margin(0.002, 0, 0, 0.004), 0.002);
}

TEST(ContactMargin, ToolSpeedIsTheFastestPointOfAnyToolIncludingACapsulesTurningEnd) {
  const double dt = 1e-3;
  // kSphere moves 1 mm per substep; kCapsule (length kCapsule.shape.length) turns by 90
  // degrees about its tip in one substep, its far end moving sqrt(2) lengths.
  const std::vector<ContactTool> tools = {kSphere, kCapsule};
  const std::vector<ToolMotion> motion = {
      {{Vec3(0, 0, 0), Vec3::UnitZ()}, {Vec3(0.001, 0, 0), Vec3::UnitZ()}},
      {{Vec3(0, 0, 1), Vec3::UnitZ()}, {Vec3(0, 0, 1), Vec3::UnitZ()}},
      {{Vec3(0.001, 0, 0), Vec3::UnitZ()}, {Vec3(0.001, 0, 0), Vec3::UnitZ()}},
      {{Vec3(0, 0, 1), Vec3::UnitZ()}, {Vec3(0, 0, 1), Vec3::UnitX()}}};
  EXPECT_NEAR(tool_speed(tools, motion, dt),
              std::max(0.001, std::sqrt(2.0) * kCapsule.shape.length) / dt, 1e-9);
  EXPECT_DOUBLE_EQ(tool_speed({kSphere}, {motion[0]}, dt), 1.0);
  EXPECT_DOUBLE_EQ(tool_speed(tools, {}, dt), 0.0);
}

TEST(ContactSweptBounds, UnionOverSubstepsAndTools) {
  const std::vector<ContactTool> tools = {kSphere, kCapsule};
  // Two substeps x two tools, row-major by substep.
  const std::vector<ToolMotion> motion = {
      {{Vec3(0, 0, 0), Vec3::UnitZ()}, {Vec3(0.1, 0, 0), Vec3::UnitZ()}},    // sphere, step 0
      {{Vec3(0, 0, 1), Vec3::UnitZ()}, {Vec3(0, 0, 1), Vec3::UnitZ()}},      // capsule, step 0
      {{Vec3(0.1, 0, 0), Vec3::UnitZ()}, {Vec3(0.2, 0, 0), Vec3::UnitZ()}},  // sphere, step 1
      {{Vec3(0, 0, 1), Vec3::UnitZ()}, {Vec3(0, 0, 1), -Vec3::UnitY()}}};    // capsule, step 1
  const Bounds b = swept_bounds(tools, motion);
  EXPECT_NEAR((b.min - Vec3(-0.01, -0.06, -0.01)).norm(), 0, 1e-15);
  EXPECT_NEAR((b.max - Vec3(0.21, 0.01, 1.06)).norm(), 0, 1e-15);
  EXPECT_TRUE(swept_bounds({}, motion).empty());
  EXPECT_TRUE(swept_bounds(tools, {}).empty());
}

}  // namespace
}  // namespace phyxel
