#include "engine/surgery/cut_faces.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <stdexcept>
#include <string>

namespace phyxel {
namespace {

// Points whose covariance's middle eigenvalue is below this fraction of the largest lie on a
// line (to ~1e-5 of their spread): no plane through them is defined.
constexpr double kCollinear = 1e-10;

}  // namespace

Vec3 CutFaces::fit_normal(const Vec3& x0, const std::vector<Vec3>& points, const Vec3& toward,
                          bool* fitted) {
  if (fitted != nullptr) *fitted = false;
  if (points.empty()) return toward.squaredNorm() > 0 ? toward.normalized() : Vec3::UnitZ();
  Vec3 mean = Vec3::Zero();
  for (const Vec3& p : points) mean += p;
  mean /= double(points.size());
  Vec3 side = mean - x0;  // from the phyxel toward its crossing points
  double scale = 0;       // the points' extent around x0, for relative tolerances
  for (const Vec3& p : points) scale = std::max(scale, (p - x0).norm());
  if (side.norm() <= 1e-12 * scale || scale == 0) side = toward;
  if (points.size() >= 3) {
    // Total least squares (eqs 18-20 generalised, see cut_faces.h): the plane through the
    // centroid whose normal is the covariance's eigenvector of the smallest eigenvalue.
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (const Vec3& p : points) cov += (p - mean) * (p - mean).transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);  // ascending eigenvalues
    const Vec3 lambda = eig.eigenvalues();
    if (eig.info() == Eigen::Success && lambda(2) > 0 && lambda(1) > kCollinear * lambda(2)) {
      Vec3 n = eig.eigenvectors().col(0).normalized();
      double along = n.dot(side);
      if (std::abs(along) <= 1e-12 * scale) along = n.dot(toward);  // x0 in the plane
      if (fitted != nullptr) *fitted = true;
      return along < 0 ? Vec3(-n) : n;
    }
  }
  return side.squaredNorm() > 0 ? side.normalized() : Vec3::UnitZ();
}

void CutFaces::add(const PhyxelSet& set, const std::vector<SeveredPair>& pairs) {
  const size_t first_changed = changed_.size();
  for (const SeveredPair& pair : pairs) {
    if (pair.i >= set.size() || pair.j >= set.size() || pair.i == pair.j) {
      throw std::invalid_argument("CutFaces::add: pair (" + std::to_string(pair.i) + ", " +
                                  std::to_string(pair.j) + ") of a set of " +
                                  std::to_string(set.size()) + " phyxels");
    }
    const Vec3& xi = set.rest[pair.i];
    const Vec3& xj = set.rest[pair.j];
    const Vec3 p = xi + double(pair.t) * (xj - xi);
    const Vec3 dir = (xj - xi).normalized();
    for (const uint32_t k : {pair.i, pair.j}) {
      CutFace& face = faces_[k];
      face.points.push_back(p);
      face.toward += k == pair.i ? dir : Vec3(-dir);
      face.torn = face.torn || pair.torn;
      changed_.push_back(k);
    }
  }
  // Refit each changed face once, however many points it got.
  std::sort(changed_.begin() + first_changed, changed_.end());
  changed_.erase(std::unique(changed_.begin() + first_changed, changed_.end()), changed_.end());
  for (size_t c = first_changed; c < changed_.size(); ++c) {
    const uint32_t k = changed_[c];
    CutFace& face = faces_[k];
    const Vec3& x0 = set.rest[k];
    face.normal = fit_normal(x0, face.points, face.toward, &face.fitted);
    face.centroid = Vec3::Zero();
    for (const Vec3& p : face.points) face.centroid += p;
    face.centroid /= double(face.points.size());
    face.offset = (face.centroid - x0).dot(face.normal);
  }
}

std::vector<uint32_t> CutFaces::take_changed() {
  std::sort(changed_.begin(), changed_.end());
  changed_.erase(std::unique(changed_.begin(), changed_.end()), changed_.end());
  std::vector<uint32_t> out;
  out.swap(changed_);
  return out;
}

const CutFace* CutFaces::face(uint32_t phyxel) const {
  const auto it = faces_.find(phyxel);
  return it == faces_.end() ? nullptr : &it->second;
}

}  // namespace phyxel
