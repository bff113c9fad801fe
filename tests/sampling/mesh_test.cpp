// OBJ meshes: loading and its errors, the winding-number inside test, and mesh sampling
// compared with the analytic shapes.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>

#include "engine/geometry/mesh.h"
#include "engine/geometry/mesh_query.h"
#include "engine/geometry/shape.h"
#include "engine/sampling/phyxel_set.h"
#include "engine/sampling/sampling_region.h"
#include "mesh_helpers.h"

namespace phyxel::test {
namespace {

std::shared_ptr<const TriangleMesh> load(const std::filesystem::path& path, double scale) {
  return std::make_shared<const TriangleMesh>(load_obj_mesh(path, scale));
}

double signed_volume(const TriangleMesh& m) {
  double v = 0;
  for (const auto& t : m.triangles)
    v += m.vertices[t[0]].dot(m.vertices[t[1]].cross(m.vertices[t[2]])) / 6;
  return v;
}

TEST(ObjMesh, QuadFacesAreTriangulatedAndScaled) {
  const TriangleMesh m = load_obj_mesh(mesh_fixture("cube.obj"), 0.1);
  EXPECT_EQ(m.vertices.size(), 8u);
  EXPECT_EQ(m.triangles.size(), 12u);
  EXPECT_EQ(m.bounds.min(), Vec3::Zero());
  EXPECT_NEAR((m.bounds.max() - Vec3::Constant(0.1)).norm(), 0, 1e-15);
  EXPECT_NEAR(signed_volume(m), 1e-3, 1e-15);
}

TEST(ObjMesh, WindingNumberIsOneInsideAndZeroOutside) {
  const TriangleMesh m = load_obj_mesh(mesh_fixture("cube.obj"), 1);
  const MeshQuery query(m);
  for (const Vec3& p : {Vec3(0.5, 0.5, 0.5), Vec3(1e-9, 0.5, 0.5), Vec3(0.999999, 1e-7, 0.999)}) {
    EXPECT_NEAR(winding_number_direct(m, p), 1, 1e-6) << p.transpose();
    EXPECT_NEAR(query.winding_number(p), 1, 1e-6) << p.transpose();
    EXPECT_TRUE(m.contains(p));
  }
  for (const Vec3& p :
       {Vec3(1.5, 0.5, 0.5), Vec3(-1e-9, 0.5, 0.5), Vec3(1 + 1e-7, 1, 1), Vec3(0.5, 0.5, -3)}) {
    EXPECT_NEAR(winding_number_direct(m, p), 0, 1e-6) << p.transpose();
    EXPECT_FALSE(m.contains(p));
  }
  // On the surface only the boundary tolerance decides.
  Shape cube = mesh_shape(std::make_shared<const TriangleMesh>(m));
  EXPECT_TRUE(shape_contains(cube, Vec3(1, 0.3, 0.7), 1e-12));
  EXPECT_TRUE(shape_contains(cube, Vec3(1, 1, 1), 1e-12));
  EXPECT_FALSE(shape_contains(cube, Vec3(1 + 1e-6, 0.3, 0.7), 1e-9));
  EXPECT_TRUE(shape_contains(cube, Vec3(1 + 1e-6, 0.3, 0.7), 1e-5));
  EXPECT_EQ(shape_bounds(cube).max(), Vec3(1, 1, 1));
}

TEST(ObjMesh, FastWindingNumberAgreesWithTheDirectSum) {
  const auto path = write_file(test_dir() / "icosphere.obj", icosphere_obj(3));
  const TriangleMesh m = load_obj_mesh(path, 1);
  EXPECT_EQ(m.triangles.size(), 1280u);
  const MeshQuery query(m);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uniform(-1.5, 1.5);
  double worst = 0;
  for (int n = 0; n < 3000; ++n) {
    const Vec3 p(uniform(rng), uniform(rng), uniform(rng));
    const double direct = winding_number_direct(m, p);
    worst = std::max(worst, std::abs(query.winding_number(p) - direct));
    EXPECT_EQ(query.contains(p, 0), direct > 0.5) << p.transpose();
    EXPECT_EQ(query.contains_near(p, 0), direct > 0.5) << p.transpose();
    EXPECT_NEAR(query.surface_distance(p), surface_distance_direct(m, p), 1e-12);
  }
  EXPECT_LT(worst, 0.02);
}

TEST(ObjMesh, SubcellTestAgreesWithTheWindingNumber) {
  const auto path = write_file(test_dir() / "icosphere.obj", icosphere_obj(2));
  const TriangleMesh m = load_obj_mesh(path, 1);
  const MeshQuery query(m);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> uniform(-1.2, 1.2);
  int mixed = 0;
  for (int n = 0; n < 400; ++n) {
    const Vec3 center(uniform(rng), uniform(rng), uniform(rng));
    const double side = 0.2;
    const uint64_t mask =
        query.inside_subcells(center, side, winding_number_direct(m, center) > 0.5, 0);
    for (int bit = 0; bit < 64; ++bit) {
      const Vec3 q = center + side * subcell_offset(bit);
      EXPECT_EQ((mask >> bit) & 1, winding_number_direct(m, q) > 0.5 ? 1u : 0u) << q.transpose();
    }
    mixed += mask != 0 && mask != ~uint64_t(0);
  }
  EXPECT_GT(mixed, 20);  // enough cells straddle the surface to test the sign rule
}

TEST(ObjMesh, InwardFacingSurfacesAreTurnedOutward) {
  const auto path =
      write_file(test_dir() / "inward.obj", cube_obj("f 1 2 3 4\nf 5 8 7 6\nf 1 5 6 2\nf 2 6 7 3\n"
                                                     "f 3 7 8 4\nf 4 8 5 1\n"));
  const TriangleMesh m = load_obj_mesh(path, 1);
  EXPECT_NEAR(signed_volume(m), 1, 1e-12);
  EXPECT_TRUE(m.contains(Vec3(0.5, 0.5, 0.5)));
}

TEST(ObjMesh, RepeatedPositionsAreWelded) {
  // Every face with its own copies of the corners, as some exporters write them.
  std::ostringstream obj;
  const char* faces[] = {"1 4 3 2", "5 6 7 8", "1 2 6 5", "2 3 7 6", "3 4 8 7", "4 1 5 8"};
  const char* corners[] = {"0 0 0", "1 0 0", "1 1 0", "0 1 0", "0 0 1", "1 0 1", "1 1 1", "0 1 1"};
  int next = 1;
  for (const char* face : faces) {
    std::istringstream ids(face);
    std::ostringstream f;
    f << "f";
    for (int id; ids >> id;) {
      obj << "v " << corners[id - 1] << "\n";
      f << " " << next++;
    }
    obj << f.str() << "\n";
  }
  const TriangleMesh m = load_obj_mesh(write_file(test_dir() / "split.obj", obj.str()), 1);
  EXPECT_EQ(m.vertices.size(), 8u);
  EXPECT_NEAR(signed_volume(m), 1, 1e-12);
}

TEST(ObjMeshErrors, MissingFile) {
  const std::string message = load_error("/nonexistent/liver.obj");
  EXPECT_NE(message.find("cannot open /nonexistent/liver.obj: check the path"), std::string::npos)
      << message;
}

TEST(ObjMeshErrors, OpenSurface) {
  const std::string message = load_error(mesh_fixture("open_cube.obj"));
  EXPECT_NE(message.find("open_cube.obj: the surface is not closed: 4 edges"), std::string::npos)
      << message;
  EXPECT_NE(message.find("closed"), std::string::npos) << message;
  EXPECT_NE(message.find("check every edge is shared by exactly two triangles"), std::string::npos)
      << message;
  EXPECT_EQ(message.find('\n'), std::string::npos);
}

TEST(ObjMeshErrors, InconsistentOrientation) {
  // The top face written clockwise.
  const auto path =
      write_file(test_dir() / "flipped_top.obj",
                 cube_obj("f 1 4 3 2\nf 5 8 7 6\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n"));
  const std::string message = load_error(path);
  EXPECT_NE(message.find("flipped_top.obj: the triangles are not consistently oriented"),
            std::string::npos)
      << message;
}

TEST(ObjMeshErrors, NoFacesBadIndicesAndParseErrors) {
  const auto dir = test_dir();
  std::string message = load_error(write_file(dir / "points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n"));
  EXPECT_NE(message.find("points.obj: the file has no triangle"), std::string::npos) << message;
  message = load_error(write_file(dir / "far_index.obj", cube_obj("f 1 2 9\n")));
  EXPECT_NE(message.find("far_index.obj: "), std::string::npos) << message;
  EXPECT_NE(message.find("vertices defined in the file"), std::string::npos) << message;
  message = load_error(write_file(dir / "zero_index.obj", cube_obj("f 0 1 2\n")));
  EXPECT_NE(message.find("zero_index.obj: cannot parse the OBJ file: "), std::string::npos)
      << message;
  EXPECT_EQ(message.find('\n'), std::string::npos);
}

// Fuzzing (docs/decisions.md) found undefined behaviour in tinyobjloader on skin-weight lines
// and on 10-digit exponents: only geometry statements reach it, and such exponents are refused.
TEST(ObjMesh, StatementsBeyondGeometryAreIgnored) {
  const std::string extras =
      "mtllib none.mtl\nusemtl skin\nvw 0 1e38 0.5\nvw 1 12147483647010 1\nt crease 1/2/3 1 2\n"
      "l 1 2\np 3\ns 1\n# a comment 1e-2147483648\ng e1234567890\n";
  const TriangleMesh m =
      load_obj_mesh(write_file(test_dir() / "extras.obj", extras + cube_obj(kCubeFaces)), 1);
  EXPECT_EQ(m.vertices.size(), 8u);
  EXPECT_EQ(m.triangles.size(), 12u);
  EXPECT_NEAR(signed_volume(m), 1, 1e-12);
}

TEST(ObjMeshErrors, ExponentsOfTenDigitsAreRefusedWithTheirLine) {
  // Lines end in "\r\n" and a lone "\r" here: both count as one line, as in tinyobjloader.
  const std::string obj = "v 0 0 0\r\nv 1 0 0\rv 1e-0000000005 1 0\nv 0 0 1e-2147483648\n";
  const std::string message =
      load_error(write_file(test_dir() / "exponent.obj", obj + std::string(kCubeFaces)));
  EXPECT_NE(message.find("exponent.obj: line 4: a number's exponent has more than 9 digits"),
            std::string::npos)
      << message;
  EXPECT_EQ(message.find('\n'), std::string::npos);
}

// Samples an object of the given shape at spacing s.
PhyxelSet sample(const Shape& shape, double s) {
  return sample_scene(scene_of({object("o", shape, s)}));
}

TEST(MeshSampling, CubeMeshSamplesExactlyLikeTheBox) {
  const Shape cube = mesh_shape(load(mesh_fixture("cube.obj"), 0.1));
  for (const double s : {0.0125, 0.01}) {
    const PhyxelSet from_mesh = sample(cube, s);
    const PhyxelSet from_box = sample(box(Vec3::Zero(), Vec3::Constant(0.1)), s);
    const size_t per_axis = size_t(std::lround(0.1 / s)) + 1;
    ASSERT_EQ(from_mesh.size(), per_axis * per_axis * per_axis);
    ASSERT_EQ(from_mesh.size(), from_box.size());
    for (size_t i = 0; i < from_box.size(); ++i) {
      EXPECT_EQ(from_mesh.rest[i], from_box.rest[i]);
      EXPECT_EQ(from_mesh.volume[i], from_box.volume[i]) << i;
      EXPECT_EQ(from_mesh.flags[i], from_box.flags[i]) << i;
      EXPECT_NEAR((from_mesh.normal[i] - from_box.normal[i]).norm(), 0, 1e-12) << i;
      EXPECT_EQ(from_mesh.splat_radius[i], from_box.splat_radius[i]);
    }
    EXPECT_NEAR(total_volume(from_mesh), 1e-3, 1e-15);
  }
}

TEST(MeshSampling, OctahedronMatchesItsAnalyticInsideTest) {
  const double r = 0.05, s = 0.0025;  // 20 spacings from the centre to a vertex
  const PhyxelSet set = sample(mesh_shape(load(mesh_fixture("octahedron.obj"), r)), s);
  size_t expected = 0;
  for (int i = -20; i <= 20; ++i)
    for (int j = -20; j <= 20; ++j)
      for (int k = -20; k <= 20; ++k) expected += std::abs(i) + std::abs(j) + std::abs(k) <= 20;
  EXPECT_EQ(set.size(), expected);
  EXPECT_NEAR(total_volume(set), 4.0 / 3.0 * r * r * r, 0.002 * 4.0 / 3.0 * r * r * r);
  for (size_t i = 0; i < set.size(); ++i) {
    const Vec3& p = set.rest[i];
    ASSERT_LE(p.lpNorm<1>(), r + 1e-12);
    if (!(set.flags[i] & kSurface)) continue;
    EXPECT_NEAR(set.normal[i].norm(), 1, 1e-12);
    EXPECT_GT(set.normal[i].dot(p), 0);
    // On a face (not an edge or vertex) the normal is the face's.
    if (std::abs(p.lpNorm<1>() - r) < 1e-12 && (p.array().abs() > 1e-12).all()) {
      EXPECT_NEAR((set.normal[i] - p.array().sign().matrix() / std::sqrt(3.0)).norm(), 0, 1e-12);
    }
  }
}

TEST(MeshSampling, IcosphereIsSampledLikeABall) {
  const auto path = write_file(test_dir() / "icosphere.obj", icosphere_obj(3));
  const auto mesh = load(path, 0.02);
  const double s = 0.001;
  const PhyxelSet set = sample(mesh_shape(mesh), s);
  const double volume = signed_volume(*mesh);
  EXPECT_NEAR(total_volume(set), volume, 0.002 * volume);
  size_t surface = 0;
  for (size_t i = 0; i < set.size(); ++i) {
    const Vec3 d = set.rest[i] - mesh->bounds.center();
    ASSERT_LE(d.norm(), 0.02 + 1e-9);
    if (!(set.flags[i] & kSurface)) continue;
    ++surface;
    EXPECT_NEAR(set.normal[i].norm(), 1, 1e-12);
    EXPECT_GT(set.normal[i].dot(d.normalized()), 0.95) << d.transpose();
  }
  EXPECT_GT(double(surface), 2 * 3.14 * 400);  // 2 pi r^2 / s^2: ends of the x lines alone
}

TEST(MeshSampling, NonConvexPrismMatchesItsTwoBoxes) {
  const double s = 0.0025;  // the prism is 0.02 x 0.02 x 0.01: 8 spacings per unit of the L
  const auto path = write_file(test_dir() / "l_prism.obj", l_prism_obj());
  const PhyxelSet set = sample(mesh_shape(load(path, 0.01)), s);
  const Shape a = box(Vec3::Zero(), Vec3(0.02, 0.01, 0.01));
  const Shape b = box(Vec3::Zero(), Vec3(0.01, 0.02, 0.01));
  // 9 x 9 x 5 sites, minus the 4 x 4 x 5 of the notch.
  ASSERT_EQ(set.size(), 9u * 9u * 5u - 4u * 4u * 5u);
  for (size_t i = 0; i < set.size(); ++i) {
    const Vec3& p = set.rest[i];
    ASSERT_TRUE(shape_contains(a, p, 1e-12) || shape_contains(b, p, 1e-12)) << p.transpose();
    // Every cell that a face of the L cuts is cut in half, two faces a quarter, and so on;
    // on the concave edge three quarters of the cell are inside.
    if (std::abs(p.x() - 0.01) < 1e-12 && std::abs(p.y() - 0.01) < 1e-12 && p.z() > 1e-12 &&
        p.z() < 0.01 - 1e-12) {
      EXPECT_DOUBLE_EQ(set.volume[i], 0.75 * s * s * s);
      EXPECT_FALSE(set.flags[i] & kSurface);  // all six face neighbours are inside
    }
    if ((set.flags[i] & kSurface) && std::abs(p.y() - 0.01) < 1e-12 && p.x() > 0.01 + 1e-12 &&
        p.x() < 0.02 - 1e-12 && p.z() > 1e-12 && p.z() < 0.01 - 1e-12) {
      EXPECT_NEAR((set.normal[i] - Vec3::UnitY()).norm(), 0, 1e-12) << p.transpose();
    }
  }
  EXPECT_NEAR(total_volume(set), 3e-6, 1e-12 * 3e-6);
}

TEST(MeshSampling, MeshesAsInclusionAndFixedRegions) {
  ObjectDesc o = object("block", box(Vec3::Constant(-0.03), Vec3::Constant(0.03)), 0.0025);
  Inclusion tumour;
  tumour.shape = mesh_shape(load(mesh_fixture("octahedron.obj"), 0.01));
  tumour.material = tissue(1500);
  o.inclusions.push_back(tumour);
  o.fixed.push_back(mesh_shape(load(mesh_fixture("cube.obj"), 0.005)));  // [0, 5 mm]^3
  const PhyxelSet set = sample_scene(scene_of({o}));
  int in_tumour = 0, fixed = 0;
  for (size_t i = 0; i < set.size(); ++i) {
    const Vec3& p = set.rest[i];
    const bool tumour_expected = p.lpNorm<1>() <= 0.01 + 1e-12;
    EXPECT_EQ(set.material[i], tumour_expected ? 1u : 0u) << p.transpose();
    in_tumour += tumour_expected;
    const bool fixed_expected = (p.array() >= -1e-12).all() && (p.array() <= 0.005 + 1e-12).all();
    EXPECT_EQ((set.flags[i] & kFixed) != 0, fixed_expected) << p.transpose();
    fixed += fixed_expected;
  }
  EXPECT_EQ(in_tumour, 129);  // sites with |i| + |j| + |k| <= 4
  EXPECT_EQ(fixed, 27);
}

TEST(MeshSampling, MeshSmallerThanTheSpacingHasNoPhyxel) {
  Scene scene =
      scene_of({object("speck", mesh_shape(load(mesh_fixture("octahedron.obj"), 0.001)), 0.005)});
  scene.file = "/tmp/surgery.json";
  const std::string message = scene_error([&] { sample_scene(scene); });
  EXPECT_NE(message.find("/tmp/surgery.json: objects[0].shape: no lattice point"),
            std::string::npos)
      << message;
  EXPECT_NE(message.find("objects[0].spacing"), std::string::npos) << message;
}

}  // namespace
}  // namespace phyxel::test
